// The simulated D435i depth stream through the real Z16 decoder: depth back-projects onto the
// geometry an independent ray cast finds, within the stereo error model; zeros appear where a
// stereo pair cannot measure; the metadata is the depth node's.

#include "tools/sim/depth_camera.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/payload_pool.hpp"
#include "daemon/config/config_loader.hpp"
#include "drivers/camera/d4xx_metadata.hpp"
#include "drivers/camera/frame_decoder.hpp"
#include "tests/unit/sim/test_scene.hpp"
#include "tools/sim/rig_config.hpp"
#include "tools/sim/scenarios.hpp"

namespace posed::sim {
// Named rather than anonymous: test files build as unity batches.
namespace depth_camera_test {

namespace cam = drivers::camera;

/// The D435i depth node of config/posed.yaml's defaults, on the colour camera's mount.
DepthCameraConfig m2dgr_depth() {
  const SimRig rig = rig_from_config(config::default_config());
  DepthCameraConfig c = rig.depth;
  c.T_base_depth = rig.T_imu_cam * rig.T_cam_depth;
  return c;
}

ClockModel d435i_clock() { return ClockModel({5'000'000'000, 12.0, 0, 0}, 0, 1); }

/// Z16 bytes through drivers/camera's decoder to metres per pixel (0 = no depth).
std::vector<double> decode_z16(const std::vector<std::byte>& bytes, const DepthCameraConfig& c) {
  cam::FrameDecoderConfig dc;
  dc.format = cam::WireFormat::kZ16;
  dc.width = static_cast<std::uint32_t>(c.intrinsics.width);
  dc.height = static_cast<std::uint32_t>(c.intrinsics.height);
  dc.depth_unit_m = static_cast<float>(c.depth_unit_m);
  cam::FrameDecoder decoder(dc);
  PayloadPool pool(1, decoder.output_bytes());
  Image image;
  EXPECT_EQ(decoder.decode(bytes, 0, pool, image), cam::DecodeStatus::kOk);
  EXPECT_EQ(image.format, PixelFormat::kDepth16);
  std::vector<double> z(dc.width * dc.height);
  const auto px = image.pixels.as<std::uint16_t>();
  for (std::size_t i = 0; i < z.size(); ++i) z[i] = px[i] * static_cast<double>(image.depth_unit_m);
  return z;
}

TEST(DepthCamera, BackProjectsOntoTheCastGeometryWithinTheStereoErrorModel) {
  // A moving vehicle in two worlds: a lit, textured room and a dim corridor with plain walls
  // where only the projector gives texture. Each valid pixel's depth is back-projected through
  // the intrinsics and compared with an independent cast of that pixel's ray through the BVH
  // (not the renderer's grid and plane shortcut).
  // Bound: the modelled error is a disparity error n·σ (σ = subpixel_rms_px, n from a table of
  // 65536 N(0, 1) draws, so |n| < 5), hence z_meas lies in [fb/(d + 5σ), fb/(d − 5σ)] with
  // d = fb/z, fb = fx·baseline, plus half a depth unit of rounding. Only speckle (wrong
  // disparities by design, ~0.3 % of matches) may fall outside, and the normalised disparity
  // error must have unit RMS (beyond 1 m, where the 1 mm rounding is < 0.3 % of σ).
  const DepthCameraConfig config = m2dgr_depth();
  const double fx = config.intrinsics.fx, fy = config.intrinsics.fy;
  const double cx = config.intrinsics.cx, cy = config.intrinsics.cy;
  const double fb = fx * config.baseline_m, sigma = config.subpixel_rms_px;
  std::uint64_t valid = 0, outside = 0, rms_n = 0;
  double sum_n2 = 0;
  for (const char* name : {"room", "corridor"}) {
    std::string error;
    auto s = make_scenario(name, 5, 20.0, 9.805, error);
    ASSERT_TRUE(s) << error;
    const Bvh bvh(s->world);
    DepthCamera depth(config, {s->world, bvh, s->trajectory}, d435i_clock(), 7);
    std::vector<std::byte> bytes;
    DepthFrameTruth truth;
    std::uint64_t frame_valid = 0;
    while (depth.next_send() < Duration::from_s(12)) {
      depth.emit(bytes, &truth);
      if (depth.frames() % 20 != 0) continue;  // every 20th frame: the vehicle has moved on
      const std::vector<double> z = decode_z16(bytes, config);
      const Eigen::Isometry3d& T = truth.T_map_depth;
      for (int y = 0; y < config.intrinsics.height; y += 2)
        for (int x = 0; x < config.intrinsics.width; x += 2) {
          const auto i = static_cast<std::size_t>(y * config.intrinsics.width + x);
          if (z[i] == 0.0) continue;
          ++frame_valid;
          const Eigen::Vector3d ray((x - cx) / fx, (y - cy) / fy, 1.0);
          const auto hit = bvh.cast(T.translation(), T.linear() * ray.normalized(), 150.0);
          ASSERT_TRUE(hit) << name << " pixel " << x << "," << y << " has depth but no surface";
          const double z_cast = hit->t_m / ray.norm();
          const double d = fb / z_cast;
          const double lo = fb / (d + 5 * sigma) - 0.5 * config.depth_unit_m - 1e-6;
          const double hi = d > 5 * sigma ? fb / (d - 5 * sigma) + 0.5 * config.depth_unit_m : 1e9;
          outside += (z[i] < lo || z[i] > hi) ? 1 : 0;
          if (z_cast > 1.0 && z[i] >= lo && z[i] <= hi) {
            const double n = (fb / z[i] - d) / sigma;
            sum_n2 += n * n;
            ++rms_n;
          }
        }
    }
    EXPECT_GT(frame_valid, 100'000u) << name << ": most of a near scene has depth";
    valid += frame_valid;
  }
  const double outside_fraction = static_cast<double>(outside) / static_cast<double>(valid);
  EXPECT_GT(outside_fraction, 0.0005);  // speckle is there
  EXPECT_LT(outside_fraction, 2 * config.speckle_fraction);
  ASSERT_GT(rms_n, 50'000u);
  EXPECT_NEAR(std::sqrt(sum_n2 / static_cast<double>(rms_n)), 1.0, 0.05);
}

TEST(DepthCamera, NoiseFreeDepthIsTheCastDepthToTheUnit) {
  DepthCameraConfig config = m2dgr_depth();
  config.noise = false;
  std::string error;
  auto s = make_scenario("room", 3, 10.0, 9.805, error);
  ASSERT_TRUE(s) << error;
  const Bvh bvh(s->world);
  DepthCamera depth(config, {s->world, bvh, s->trajectory}, d435i_clock(), 1);
  std::vector<std::byte> bytes;
  DepthFrameTruth truth;
  while (depth.next_send() < Duration::from_s(6)) depth.emit(bytes, &truth);
  const std::vector<double> z = decode_z16(bytes, config);
  double max_err = 0;
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (truth.pixel[i] != DepthPixel::kValid) {
      EXPECT_EQ(z[i], 0.0);
      continue;
    }
    max_err = std::max(max_err, std::abs(z[i] - truth.z_m[i]));
    ++n;
  }
  EXPECT_GT(n, 200'000u);
  EXPECT_LE(max_err, 0.5 * config.depth_unit_m + 1e-6);  // rounding to the unit, float z
}

/// A camera facing a wall 3 m away with a 0.4 m box 1 m in front of it, both lit and textured.
struct WallAndBox {
  explicit WallAndBox(DepthCameraConfig c, double ambient = 0.5, bool textured = true)
      : config(std::move(c)), scene(config.T_base_depth) {
    World& w = scene.world();
    w.ambient = ambient;
    const auto wall = w.add_material({40,
                                      0.6,
                                      textured ? kTextureNoise : kTexturePlain,
                                      textured ? 0.5 : 0.0,
                                      20,
                                      0,
                                      {1, 1, 1}});
    scene.add_box({0, 0, 3.1}, {20, 20, 0.1}, wall);
    scene.add_box({0, 0, 1.1}, {0.2, 0.2, 0.1}, wall);
    config.noise = false;
  }
  /// One frame: decoded depth and what the camera says about each pixel.
  std::vector<double> frame(DepthFrameTruth& truth) {
    DepthCamera depth(config, scene.finish(), d435i_clock(), 3);
    std::vector<std::byte> bytes;
    depth.emit(bytes, &truth);
    return decode_z16(bytes, config);
  }
  double at(const std::vector<double>& z, int x, int y) const {
    return z[static_cast<std::size_t>(y * config.intrinsics.width + x)];
  }

  DepthCameraConfig config;
  test::CameraTestScene scene;
};

TEST(DepthCamera, ZerosWhereTheRightImagerIsBlind) {
  WallAndBox s(m2dgr_depth());
  DepthFrameTruth truth;
  const std::vector<double> z = s.frame(truth);
  const CameraIntrinsics& K = s.config.intrinsics;
  const double fb = K.fx * s.config.baseline_m;
  // The box's left edge (x = -0.2 m at z = 1 m) and the background band it hides from the
  // right imager: d_box - d_wall pixels wide, to the left of the edge.
  const double edge = K.cx - K.fx * 0.2;
  const double band = fb / 1.0 - fb / 3.0;
  for (int y = static_cast<int>(K.cy) - 30; y <= static_cast<int>(K.cy) + 30; ++y) {
    for (int x = static_cast<int>(std::ceil(edge - band + 1.5)); x < edge - 1; ++x)
      EXPECT_EQ(s.at(z, x, y), 0.0) << "occluded background at " << x << "," << y;
    for (int x = static_cast<int>(edge - band - 12); x < edge - band - 2; ++x)
      EXPECT_NEAR(s.at(z, x, y), 3.0, 0.001) << "visible background at " << x << "," << y;
    for (int x = static_cast<int>(edge) + 2; x < K.cx + K.fx * 0.2 - 2; ++x)
      EXPECT_NEAR(s.at(z, x, y), 1.0, 0.001) << "box at " << x << "," << y;
  }
  // The image's left edge: the right imager's view starts d_wall pixels in.
  for (int y = 0; y < K.height; y += 7) {
    for (int x = 0; x < static_cast<int>(fb / 3.0); ++x) EXPECT_EQ(s.at(z, x, y), 0.0) << x;
    EXPECT_NEAR(s.at(z, static_cast<int>(fb / 3.0) + 2, y), 3.0, 0.001);
  }
}

TEST(DepthCamera, ZerosOutsideTheWorkingRange) {
  DepthCameraConfig c = m2dgr_depth();
  c.max_range_m = 2.5;  // the wall at 3 m is too far, the box at 1 m is not
  WallAndBox s(c);
  DepthFrameTruth truth;
  const std::vector<double> z = s.frame(truth);
  const CameraIntrinsics& K = s.config.intrinsics;
  EXPECT_EQ(s.at(z, 100, 100), 0.0);
  EXPECT_EQ(truth.pixel[100 * static_cast<std::size_t>(K.width) + 100], DepthPixel::kOutOfRange);
  EXPECT_NEAR(s.at(z, static_cast<int>(K.cx), static_cast<int>(K.cy)), 1.0, 0.001);
  c = m2dgr_depth();
  c.min_range_m = 1.5;  // now the box is too near
  WallAndBox near(c);
  const std::vector<double> zn = near.frame(truth);
  EXPECT_EQ(near.at(zn, static_cast<int>(K.cx), static_cast<int>(K.cy)), 0.0);
  EXPECT_NEAR(near.at(zn, 100, 100), 3.0, 0.001);
}

TEST(DepthCamera, ZerosOnTexturelessSurfacesOutOfTheProjectorsReach) {
  // Dark, plain surfaces: only the projector's dots give texture. A third of the laser power
  // reaches 1 m (the box) but not 3 m (the wall); with the scene lit and textured, the wall
  // matches again.
  DepthCameraConfig c = m2dgr_depth();
  c.laser_power_mw = 50;
  WallAndBox dark(c, 0.0, false);
  DepthFrameTruth truth;
  const std::vector<double> z = dark.frame(truth);
  const CameraIntrinsics& K = c.intrinsics;
  EXPECT_EQ(dark.at(z, 100, 100), 0.0);
  EXPECT_EQ(truth.pixel[100 * static_cast<std::size_t>(K.width) + 100], DepthPixel::kLowTexture);
  EXPECT_NEAR(dark.at(z, static_cast<int>(K.cx), static_cast<int>(K.cy)), 1.0, 0.001);
  WallAndBox lit(c, 0.5, true);
  EXPECT_NEAR(lit.at(lit.frame(truth), 100, 100), 3.0, 0.001);
}

TEST(DepthCamera, ZerosOnSurfacesSeenAtGrazingIncidence) {
  // A wall through a point 2 m ahead, turned so that its normal is 75° from the optical axis:
  // across the image the angle between the normal and a pixel's ray runs from ~35° at the left
  // edge to 90° (edge-on) right of the centre.
  DepthCameraConfig c = m2dgr_depth();
  c.noise = false;
  test::CameraTestScene scene(c.T_base_depth);
  scene.world().ambient = 0.5;
  const auto wall = scene.world().add_material({40, 0.6, kTextureNoise, 0.5, 20, 0, {1, 1, 1}});
  const double yaw = 15.0 * std::numbers::pi / 180.0;
  scene.add_box({0, 0, 2.0}, {0.05, 5, 20}, wall, yaw);
  DepthCamera depth(c, scene.finish(), d435i_clock(), 3);
  std::vector<std::byte> bytes;
  DepthFrameTruth truth;
  depth.emit(bytes, &truth);
  const std::vector<double> z = decode_z16(bytes, c);
  const Eigen::Vector3d n_cam =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) * Eigen::Vector3d::UnitX();
  const CameraIntrinsics& K = c.intrinsics;
  int grazing = 0, seen = 0;
  for (int x = 0; x < K.width; ++x) {
    const auto i = static_cast<std::size_t>(static_cast<int>(K.cy) * K.width + x);
    if (truth.z_m[i] <= 0.0f || truth.pixel[i] == DepthPixel::kOccluded) continue;
    const Eigen::Vector3d ray = Eigen::Vector3d((x - K.cx) / K.fx, 0, 1).normalized();
    const double incidence_deg = std::acos(std::abs(n_cam.dot(ray))) * 180.0 / std::numbers::pi;
    if (incidence_deg > c.grazing_limit_deg) {
      EXPECT_EQ(z[i], 0.0) << x << " at " << incidence_deg << " deg";
      ++grazing;
    } else if (incidence_deg < c.grazing_limit_deg - 10.0) {
      EXPECT_GT(z[i], 0.0) << x << " at " << incidence_deg << " deg";
      ++seen;
    }
  }
  EXPECT_GT(grazing, 20);
  EXPECT_GT(seen, 20);
}

TEST(DepthCamera, MetadataIsTheDepthNodesOnTheDeviceClock) {
  const DepthCameraConfig config = m2dgr_depth();
  std::string error;
  auto s = make_scenario("corridor", 2, 5.0, 9.805, error);
  ASSERT_TRUE(s) << error;
  const Bvh bvh(s->world);
  const ClockModel clock = d435i_clock();
  const Duration phase = Duration::from_ms(17);
  DepthCamera depth(config, {s->world, bvh, s->trajectory}, clock, 4, phase);
  std::vector<std::byte> bytes, metadata;
  for (std::uint32_t k = 0; k < 30; ++k) {
    const HostTime arrival = HostTime::from_ns(depth.next_send().ns + 3'000'000);
    encode_d4xx_metadata(depth.next_metadata(arrival), metadata);
    cam::D4xxFrameMetadata md;
    ASSERT_EQ(cam::parse_d4xx_metadata(metadata, md), cam::MetadataStatus::kOk);
    EXPECT_EQ(md.frame_counter, k);
    // Exposure midpoints every 1/15 s of the device clock after its phase.
    const std::int64_t mid_ns = clock.device_at(Duration::from_ns(0)).ns + phase.ns +
                                std::llround((k + 1) * 1e9 / config.rate_hz);
    EXPECT_NEAR(md.sensor_timestamp_us, static_cast<double>(mid_ns / 1000), 1.0);
    EXPECT_EQ(md.width_px, 640);
    EXPECT_EQ(md.height_px, 480);
    EXPECT_EQ(md.fps, 15);
    ASSERT_TRUE(md.has_gain && md.has_control_exposure);
    EXPECT_EQ(md.laser_power, 150u);
    EXPECT_GE(md.gain, 16u);  // 16 = 1x
    EXPECT_LE(md.gain, 248u);
    EXPECT_EQ(md.control_exposure, md.exposure_time_us);
    EXPECT_GT(md.exposure_time_us, 0u);
    EXPECT_LE(md.exposure_time_us, md.frame_interval_us / 2);
    EXPECT_NEAR(md.sensor_timestamp_us - md.pts_us, md.exposure_time_us / 2.0, 1.0);
    depth.emit(bytes);
    EXPECT_EQ(bytes.size(), 640u * 480u * 2u);
  }
}

}  // namespace depth_camera_test
}  // namespace posed::sim
