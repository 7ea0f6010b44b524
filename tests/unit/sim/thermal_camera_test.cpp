// The PLUG 617's 16-bit raw output: frames decode through drivers/camera's Y16 path, the counts
// are the documented radiometric function of the scene temperatures (with the NETD and
// fixed-pattern noise on top), NUC freezes and resets them as in the 8-bit video, and the
// driver's AGC of them gives an image like the camera's own 8-bit output.

#include "tools/sim/thermal_camera.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/payload_pool.hpp"
#include "daemon/config/config_loader.hpp"
#include "drivers/camera/frame_decoder.hpp"
#include "tests/common/realdata.hpp"
#include "tests/unit/sim/test_scene.hpp"
#include "tools/sim/rig_config.hpp"
#include "tools/sim/scenarios.hpp"

namespace posed::sim {
// Named rather than anonymous: test files build as unity batches.
namespace thermal_camera_test {

namespace cam = drivers::camera;

ThermalCameraConfig m2dgr_thermal(ThermalFormat format) {
  const SimRig rig = rig_from_config(config::default_config());
  ThermalCameraConfig c;
  c.intrinsics = rig.thermal;
  c.T_base_cam = rig.T_imu_cam * rig.T_cam_thermal;
  c.rate_hz = rig.thermal_rate_hz;
  c.format = format;
  return c;
}

ClockModel thermal_clock() { return ClockModel({0, -40.0, 0, 0}, 0, 1); }

/// A frame through drivers/camera's decoder: Y16 to mono16 counts, or (agc) to mono8 through
/// the driver's 16 -> 8-bit AGC, or Y8 to mono8; as doubles per pixel.
std::vector<double> decode(const std::vector<std::byte>& bytes, const ThermalCameraConfig& c,
                           bool agc = false) {
  cam::FrameDecoderConfig dc;
  dc.format = c.format == ThermalFormat::kY16 ? cam::WireFormat::kY16 : cam::WireFormat::kY8;
  dc.width = static_cast<std::uint32_t>(c.intrinsics.width);
  dc.height = static_cast<std::uint32_t>(c.intrinsics.height);
  dc.y16_agc_to_mono8 = agc;
  cam::FrameDecoder decoder(dc);
  PayloadPool pool(1, decoder.output_bytes());
  Image image;
  EXPECT_EQ(decoder.decode(bytes, 0, pool, image), cam::DecodeStatus::kOk);
  std::vector<double> out(dc.width * dc.height);
  if (image.format == PixelFormat::kMono16) {
    const auto px = image.pixels.as<std::uint16_t>();
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = px[i];
  } else {
    EXPECT_EQ(image.format, PixelFormat::kMono8);
    const auto px = image.pixels.as<std::uint8_t>();
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = px[i];
  }
  return out;
}

struct Stats {
  double mean = 0, std = 0;
};
/// Mean and standard deviation over the rectangle [x0, x1) x [y0, y1).
Stats region(const std::vector<double>& v, int width, int x0, int x1, int y0, int y1) {
  double s = 0, s2 = 0, n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const double p = v[static_cast<std::size_t>(y * width + x)];
      s += p;
      s2 += p * p;
      n += 1;
    }
  return {s / n, std::sqrt(std::max(0.0, s2 / n - (s / n) * (s / n)))};
}

/// The thermal camera facing two plain walls 4 m ahead: 20 °C left of the optical axis,
/// 35 °C right of it.
struct TwoWalls {
  explicit TwoWalls(ThermalCameraConfig c) : config(std::move(c)), scene(config.T_base_cam) {
    World& w = scene.world();
    const auto cool = w.add_material({40, 0.5, kTexturePlain, 0, 20.0, 0, {1, 1, 1}});
    const auto warm = w.add_material({40, 0.5, kTexturePlain, 0, 35.0, 0, {1, 1, 1}});
    scene.add_box({-5, 0, 4.1}, {5, 10, 0.1}, cool);
    scene.add_box({5, 0, 4.1}, {5, 10, 0.1}, warm);
  }
  ThermalCamera camera(std::uint64_t seed = 5) {
    return ThermalCamera(config, scene.finish(), thermal_clock(), seed);
  }
  /// Columns well inside the left (cool) and right (warm) wall, away from the boundary that
  /// the half-resolution render blurs and from the lens' distorted corners.
  int cool_x0() const { return 120; }
  int cool_x1() const { return static_cast<int>(config.intrinsics.cx) - 8; }
  int warm_x0() const { return static_cast<int>(config.intrinsics.cx) + 8; }
  int warm_x1() const { return config.intrinsics.width - 120; }
  int y0() const { return 150; }
  int y1() const { return config.intrinsics.height - 150; }

  ThermalCameraConfig config;
  test::CameraTestScene scene;
};

TEST(ThermalRadiometry, TheDocumentedMapping) {
  // docs/simulator.md and thermal_radiometry.hpp: the real 16-bit frame's median (2699 counts)
  // is 12.5 °C, a 12 °C scene reads 2678 counts, ~43 counts/K there, and −60..150 °C fits in
  // 14 bits.
  const Radiometry r;
  EXPECT_NEAR(r.temperature_c(2699.0), 12.5, 0.05);
  EXPECT_NEAR(r.counts(12.0), 2678.0, 0.5);
  EXPECT_NEAR(r.counts(12.5) - r.counts(11.5), 43.3, 0.1);
  EXPECT_NEAR(r.counts(-60.0), 677.0, 0.5);
  EXPECT_NEAR(r.counts(150.0), 13131.0, 0.5);
  for (double t = -80.0; t < 250.0; t += 0.37) {
    EXPECT_NEAR(r.temperature_c(r.counts(t)), t, 1e-9);
    // Linear in radiance: between table points the lookup is the exact value rounded.
    const double exact = std::min(r.counts(t), 16383.0);
    EXPECT_NEAR(r.counts_u14(static_cast<float>(t)), exact, 0.51) << t;
  }
  EXPECT_EQ(r.counts_u14(400.0f), Radiometry::kMaxCounts);  // saturates like the sensor
}

TEST(ThermalRadiometry, TheRealRadiometricFrameReadsAsItsScene) {
  // The constants are the ones in the exif of shared/realdata/thermal_16bit: through them the
  // real frame, decoded by the same Y16 path as the simulated ones, is a 10.7..13.4 °C scene.
  const std::string path =
      posed::test::realdata_path("thermal_16bit/frame_000000_640x512_u16le.raw");
  if (path.empty()) GTEST_SKIP() << "no shared/realdata/thermal_16bit (POSED_REALDATA)";
  ThermalCameraConfig c = m2dgr_thermal(ThermalFormat::kY16);
  std::vector<double> counts = decode(posed::test::read_std_bytes(path), c);
  std::sort(counts.begin(), counts.end());
  const Radiometry r;
  EXPECT_NEAR(r.temperature_c(counts.front()), 10.7, 0.05);
  EXPECT_NEAR(r.temperature_c(counts[counts.size() / 2]), 12.5, 0.05);
  EXPECT_NEAR(r.temperature_c(counts.back()), 13.4, 0.05);
}

TEST(ThermalCamera, Y16CountsAreTheSceneTemperatures) {
  ThermalCameraConfig c = m2dgr_thermal(ThermalFormat::kY16);
  c.noise = false;
  TwoWalls walls(c);
  ThermalCamera ideal = walls.camera();
  std::vector<std::byte> bytes;
  ideal.emit(bytes);
  ASSERT_EQ(bytes.size(), 640u * 512u * 2u);
  const Radiometry& r = ideal.radiometry();
  std::vector<double> counts = decode(bytes, c);
  const int W = c.intrinsics.width;
  for (int y = walls.y0(); y < walls.y1(); y += 9) {
    for (int x = walls.cool_x0(); x < walls.cool_x1(); x += 3)
      ASSERT_NEAR(counts[static_cast<std::size_t>(y * W + x)], r.counts(20.0), 0.51) << x;
    for (int x = walls.warm_x0(); x < walls.warm_x1(); x += 3)
      ASSERT_NEAR(counts[static_cast<std::size_t>(y * W + x)], r.counts(35.0), 0.51) << x;
  }

  // With the sensor's noise: the same mean, and the spread the noise model predicts in counts:
  // NETD and fixed-pattern noise (per pixel, plus 0.7 of it per column; 0.03 K at start) in
  // kelvin, times the local slope of the radiometric curve.
  c.noise = true;
  TwoWalls noisy_walls(c);
  ThermalCamera noisy = noisy_walls.camera();
  noisy.emit(bytes);
  counts = decode(bytes, c);
  const double fpn_k = 0.03 + c.fpn_growth_kps * (1.0 / c.rate_hz);
  const double sigma_k = std::sqrt(c.netd_k * c.netd_k + fpn_k * fpn_k * (1 + 0.49));
  for (const auto& [x0, x1, t_c] : {std::tuple{walls.cool_x0(), walls.cool_x1(), 20.0},
                                    std::tuple{walls.warm_x0(), walls.warm_x1(), 35.0}}) {
    const Stats s = region(counts, W, x0, x1, walls.y0(), walls.y1());
    EXPECT_NEAR(r.temperature_c(s.mean), t_c, 0.01);
    const double slope = r.counts(t_c + 0.5) - r.counts(t_c - 0.5);  // [counts/K]
    EXPECT_NEAR(s.std / (slope * sigma_k), 1.0, 0.15) << t_c;
  }
}

TEST(ThermalCamera, Y16FreezesDuringNucThenThePatternStartsAfresh) {
  ThermalCameraConfig c = m2dgr_thermal(ThermalFormat::kY16);
  c.nuc_min_s = 1.0;
  c.nuc_max_s = 1.2;
  c.fpn_growth_kps = 0.5;  // a pattern that grows fast enough to see within a second
  TwoWalls walls(c);
  ThermalCamera camera = walls.camera();
  std::vector<std::byte> bytes, previous;
  std::vector<double> spread;  // of the cool wall, per frame [counts]
  int frozen = 0, first_frozen = -1;
  for (int k = 0; k < 50; ++k) {
    camera.emit(bytes);
    if (bytes == previous) {
      ++frozen;
      if (first_frozen < 0) first_frozen = k;
    }
    previous = bytes;
    spread.push_back(region(decode(bytes, c), c.intrinsics.width, walls.cool_x0(), walls.cool_x1(),
                            walls.y0(), walls.y1())
                         .std);
  }
  ASSERT_EQ(camera.nucs(), 1u);
  // The shutter closes for 0.3 s: 7 or 8 repeats of the last frame at 25 Hz.
  EXPECT_GE(frozen, 7);
  EXPECT_LE(frozen, 8);
  EXPECT_GE(first_frozen, 24);  // 1.0 s
  EXPECT_LE(first_frozen, 31);  // 1.2 s + one frame
  // The pattern had grown to ~0.5 K before; right after the NUC it is back to ~0.03 K.
  const auto after = static_cast<std::size_t>(first_frozen + frozen);
  EXPECT_GT(spread[static_cast<std::size_t>(first_frozen) - 1], 3 * spread[after]);
}

TEST(ThermalCamera, TheDriversAgcOfRawCountsLooksLikeThe8BitVideo) {
  // Same seed, same street, same noise: one camera sends y8 (its own AGC), the other y16, which
  // goes through drivers/camera's AGC (1-99 % percentile stretch). The two AGCs choose their
  // windows differently (frame range vs percentiles; temperature vs radiance, which is not
  // linear over a -30 °C sky and 70 °C lamps), so the images differ by a monotonic remapping;
  // they must still show the same scene: strongly correlated pixel for pixel, both using the
  // 8-bit range.
  std::string error;
  auto s = make_scenario("street_night", 3, 20.0, 9.805, error);
  ASSERT_TRUE(s) << error;
  const Bvh bvh(s->world);
  const SensorScene scene{s->world, bvh, s->trajectory};
  const ThermalCameraConfig c8 = m2dgr_thermal(ThermalFormat::kY8);
  const ThermalCameraConfig c16 = m2dgr_thermal(ThermalFormat::kY16);
  ThermalCamera video(c8, scene, thermal_clock(), 11), raw(c16, scene, thermal_clock(), 11);
  std::vector<std::byte> b8, b16;
  double min_correlation = 1.0;
  for (int k = 1; k <= 400; ++k) {
    video.emit(b8);
    raw.emit(b16);
    if (k % 50 != 0) continue;  // every 2 s of the drive
    const std::vector<double> a = decode(b8, c8), b = decode(b16, c16, true);
    const Stats sa = region(a, 640, 0, 640, 0, 512), sb = region(b, 640, 0, 640, 0, 512);
    double cov = 0;
    for (std::size_t i = 0; i < a.size(); ++i) cov += (a[i] - sa.mean) * (b[i] - sb.mean);
    const double correlation = cov / static_cast<double>(a.size()) / (sa.std * sb.std);
    min_correlation = std::min(min_correlation, correlation);
    EXPECT_GT(sa.std, 20.0) << k;
    EXPECT_GT(sb.std, 20.0) << k;
  }
  EXPECT_GT(min_correlation, 0.9);
}

}  // namespace thermal_camera_test
}  // namespace posed::sim
