// The camera front end of the fusion core on a scene known exactly: the M2DGR rig's colour and
// thermal cameras, standing still, look at a textured wall 6 m ahead that the lidar also sees.
// Frames, IMU samples, states and scans are handed over in stamp order as the fusion stage does.

#include "core/fusion/camera_front_end.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>

#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::fusion {
namespace {

namespace scene = vision::scene;
constexpr double kWallDepthM = 6.0;

Image to_image(const cv::Mat& grey, HostTime stamp, PayloadPool& pool) {
  Image image;
  image.stamp = stamp;
  image.width = static_cast<std::uint32_t>(grey.cols);
  image.height = static_cast<std::uint32_t>(grey.rows);
  image.stride = image.width;
  image.format = PixelFormat::kMono8;
  image.pixels = pool.acquire();
  EXPECT_TRUE(image.pixels.valid());
  for (int r = 0; r < grey.rows; ++r) {
    std::memcpy(image.pixels.bytes().data() + static_cast<std::size_t>(r) * image.stride,
                grey.ptr(r), image.width);
  }
  return image;
}

class CountingObserver final : public FrontendObserver {
 public:
  void on_frame(const vision::FrontendFrame& frame,
                const vision::VisualFrontend& frontend) override {
    ++frames[frontend.config().mode];
    for (const auto& f : frame.features) {
      if (std::isnan(f.depth_m)) {
        if (f.normalised.x() > 0.05) ++right_without_depth;
        continue;
      }
      ++depths;
      worst_depth_error_m = std::max(worst_depth_error_m, std::abs(f.depth_m - kWallDepthM));
      if (f.depth_from_stereo) {
        ++stereo_depths;
        if (f.normalised.x() < -0.05) ++stereo_left;
      }
    }
  }
  std::map<vision::FrontendMode, int> frames;
  int depths = 0;
  double worst_depth_error_m = 0;
  int stereo_depths = 0;        ///< depths from the depth image
  int stereo_left = 0;          ///< of those, on the half the lidar covers
  int right_without_depth = 0;  ///< features on the half the lidar misses, without depth
};

struct Rig {
  CameraFrontEndConfig config;
  Rig() {
    config.frontend.visible_camera = scene::m2dgr_visible();
    config.frontend.thermal_camera = scene::m2dgr_thermal();
    config.frontend.T_cam_thermal = scene::m2dgr_T_cam_thermal();
    // The IMU, the colour camera and the lidar share one frame here (camera axes).
  }
};

/// What of the wall the lidar sees, and whether a D435i depth node sees it too.
struct DepthSources {
  bool lidar_left_half_only = false;  ///< the lidar's points end at the optical axis
  /// Z16 depth images of the whole wall at 15 Hz, `offset_us` from each visible frame (before
  /// it: a frame event runs once the IMU covers it, and a depth image after it is not there
  /// yet), from the depth camera at `T_cam_depth` (null: none)
  const Eigen::Isometry3d* T_cam_depth = nullptr;
  std::int64_t offset_us = -2000;
};

/// A Z16 image of the wall z = kWallDepthM (camera frame) seen from the depth camera: a
/// fronto-parallel wall is at one depth in the depth frame too when the two frames share axes.
Image depth_image_of_wall(const Eigen::Isometry3d& T_cam_depth, HostTime stamp, PayloadPool& pool) {
  Image image;
  image.stamp = stamp;
  image.width = 640;
  image.height = 480;
  image.stride = 2 * image.width;
  image.format = PixelFormat::kDepth16;
  image.depth_unit_m = 0.001f;
  image.pixels = pool.acquire();
  EXPECT_TRUE(image.pixels.valid());
  const double z_depth_m = kWallDepthM - T_cam_depth.translation().z();
  const auto units = static_cast<std::uint16_t>(std::lround(z_depth_m / 0.001));
  for (std::size_t i = 0; i < static_cast<std::size_t>(image.width) * image.height; ++i) {
    std::memcpy(image.pixels.bytes().data() + 2 * i, &units, sizeof units);
  }
  return image;
}

/// The buffers the rig's frames live in: declared before the front end, so they outlive the
/// frames it still holds (a visible frame awaiting its partner, the newest depth images), as the
/// pipeline's camera stages outlive its fusion core.
struct RigPools {
  PayloadPool visible{16, 640 * 480};
  PayloadPool thermal{16, 640 * 512};
  PayloadPool depth{8, 640 * 480 * 2};
};

/// Hands 3 s of a still rig to `front` in stamp order; returns the visible frames sent. Thermal
/// frames stamped in [freeze_from_us, freeze_to_us) repeat the one before, byte for byte (the
/// shutter closed for a flat-field correction).
int run_still_rig(RigPools& pools, CameraFrontEnd& front, bool with_thermal, bool with_lidar,
                  std::int64_t freeze_from_us = -1, std::int64_t freeze_to_us = -1,
                  const DepthSources& depth = {}) {
  const auto vis_cam = scene::m2dgr_visible();
  const auto th_cam = scene::m2dgr_thermal();
  const cv::Mat visible = scene::render_wall(
      vis_cam, scene::pixel_rays(vis_cam), Eigen::Isometry3d::Identity(), kWallDepthM, 160, 40, 7);
  const cv::Mat thermal = scene::render_wall(th_cam, scene::pixel_rays(th_cam),
                                             scene::m2dgr_T_cam_thermal(), kWallDepthM, 120, 60, 7);
  PayloadPool &visible_pool = pools.visible, &thermal_pool = pools.thermal,
              &depth_pool = pools.depth;
  // Events in stamp order: IMU at 200 Hz, visible at 15 Hz (+3 ms), thermal at 25 Hz (+11 ms),
  // a lidar scan at 10 Hz.
  std::vector<lidar::ScanPoint> wall;
  for (int i = -100; i <= 100; ++i) {
    if (depth.lidar_left_half_only && i > 0) break;
    for (int j = -80; j <= 80; ++j) {
      lidar::ScanPoint p;
      p.p = Eigen::Vector3f(0.05f * static_cast<float>(i), 0.05f * static_cast<float>(j),
                            static_cast<float>(kWallDepthM));
      wall.push_back(p);
    }
  }
  int visible_sent = 0;
  std::uint64_t scan_index = 0;
  int noise_seed = 1;
  std::uint64_t thermal_seed = 1000;
  for (std::int64_t t_us = 0; t_us <= 3'000'000; ++t_us) {
    const HostTime t = HostTime::from_ns(t_us * 1000);
    if (t_us % 5000 == 0) {
      ImuSample s;
      s.stamp = t;
      s.specific_force_mps2 = Eigen::Vector3d(0, -9.81, 0);
      front.add_imu(s);
      NavState state;
      state.stamp = t;
      front.add_state(state);
    }
    if (with_lidar && t_us % 100'000 == 50'000) {
      MatchedScan scan;
      scan.index = ++scan_index;
      scan.stamp = t;
      scan.points_lidar = wall;
      front.add_scan(scan);
    }
    if (t_us % 66'667 == 3000) {
      front.add_image(
          CameraStream::kVisible,
          to_image(scene::add_noise(visible, 2.0, static_cast<std::uint64_t>(noise_seed++)), t,
                   visible_pool));
      ++visible_sent;
    }
    if (depth.T_cam_depth != nullptr && t_us >= 3000 + depth.offset_us &&
        (t_us - 3000 - depth.offset_us) % 66'667 == 0) {
      front.add_image(CameraStream::kDepth, depth_image_of_wall(*depth.T_cam_depth, t, depth_pool));
    }
    if (with_thermal && t_us % 40'000 == 11'000) {
      const bool frozen = t_us >= freeze_from_us && t_us < freeze_to_us;
      if (!frozen) ++thermal_seed;
      front.add_image(CameraStream::kThermal,
                      to_image(scene::add_noise(thermal, 1.0, thermal_seed), t, thermal_pool));
    }
    if (t_us % 1000 == 0) front.process(Eigen::Vector3d::Zero());
  }
  return visible_sent;
}

TEST(CameraFrontEnd, FusedModeTracksEveryPairedFrameAndTheOtherModesCompareOnTheSameEvents) {
  Rig rig;
  rig.config.frontend.mode = vision::FrontendMode::kFused;
  rig.config.compare_modes = {vision::FrontendMode::kVisible, vision::FrontendMode::kThermal};
  RigPools pools;
  CameraFrontEnd front(rig.config);
  CountingObserver observer;
  front.set_observer(&observer);
  const int sent = run_still_rig(pools, front, /*with_thermal=*/true, /*with_lidar=*/true);

  const auto& pairing = front.pairing();
  ASSERT_GT(pairing.paired, 35u);
  const CameraFigures& fused = front.figures();
  EXPECT_EQ(fused.mode, "fused");
  // Every released visible frame is one event; a visible frame near the end may still wait.
  const std::uint64_t events = pairing.paired + pairing.unpaired_visible;
  EXPECT_GE(events + 2, static_cast<std::uint64_t>(sent));
  EXPECT_EQ(fused.frames, pairing.paired);
  EXPECT_EQ(fused.frames + fused.frames_unusable, events);
  const std::vector<CameraFigures> compare = front.compare_figures();
  ASSERT_EQ(compare.size(), 2u);
  EXPECT_EQ(compare[0].mode, "visible");
  EXPECT_EQ(compare[0].frames, events);
  EXPECT_EQ(compare[1].mode, "thermal");
  EXPECT_EQ(compare[1].frames, pairing.paired);
  EXPECT_EQ(observer.frames[vision::FrontendMode::kFused], static_cast<int>(fused.frames));

  // A still textured wall: hundreds of features, nearly all tracked from frame to frame.
  EXPECT_GT(fused.features, 150);
  EXPECT_GT(fused.match_success_rate(), 0.9);
  // The wall is in the lidar too: most features get a depth, and the right one.
  EXPECT_GT(fused.depth_total, fused.features_total / 2);
  EXPECT_GT(observer.depths, 1000);
  EXPECT_LT(observer.worst_depth_error_m, 0.05);
  EXPECT_EQ(fused.thermal_frozen, 0u);
  // Both streams and the fusion were assessed.
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(fused.quality[i].valid) << i;
    EXPECT_GT(fused.quality_frames[i], 0u) << i;
  }
}

TEST(CameraFrontEnd, WithoutThermalFramesFusedEventsAreUnusableAndVisibleModeRuns) {
  Rig rig;
  rig.config.frontend.mode = vision::FrontendMode::kFused;
  rig.config.compare_modes = {vision::FrontendMode::kVisible};
  RigPools pools;
  CameraFrontEnd front(rig.config);
  const int sent = run_still_rig(pools, front, /*with_thermal=*/false, /*with_lidar=*/false);
  const CameraFigures& fused = front.figures();
  EXPECT_EQ(fused.frames, 0u);
  EXPECT_GE(fused.frames_unusable + 2, static_cast<std::uint64_t>(sent));
  const CameraFigures visible = front.compare_figures().at(0);
  EXPECT_EQ(visible.frames, fused.frames_unusable);
  EXPECT_GT(visible.features, 150);
  EXPECT_EQ(visible.depth_total, 0u);  // no lidar, no depth
}

TEST(CameraFrontEnd, FrozenThermalFramesAreLeftOut) {
  Rig rig;
  rig.config.frontend.mode = vision::FrontendMode::kThermal;
  RigPools pools;
  CameraFrontEnd front(rig.config);
  // Half a second of repeated thermal frames: the 8 events of the visible camera's 15 Hz in it
  // pair with thermal frames, the first with the new one, the 7 after it with repeats.
  run_still_rig(pools, front, /*with_thermal=*/true, /*with_lidar=*/true, 1'000'000, 1'500'000);
  const CameraFigures& thermal = front.figures();
  EXPECT_EQ(thermal.thermal_frozen, 7u);
  EXPECT_EQ(thermal.frames_unusable, 7u);
  EXPECT_GT(thermal.frames, 30u);
}

TEST(CameraFrontEnd, WhereTheLidarGivesNoDepthTheDepthImageDoesAtItsExtrinsic) {
  // The lidar sees the left half of the wall, the D435i's depth node all of it from 10 cm
  // behind the colour camera (so the depth image reads 6.1 m where the colour camera is 6 m
  // away: a front end that ignored the extrinsic would be 10 cm off).
  const Eigen::Isometry3d T_cam_depth(Eigen::Translation3d(0.0143, 0, -0.1));
  const auto run = [&](const Eigen::Isometry3d* depth_camera, std::int64_t offset_us,
                       Duration max_offset, CountingObserver& observer) {
    Rig rig;
    rig.config.frontend.mode = vision::FrontendMode::kVisible;
    rig.config.depth_image.T_cam_depth = T_cam_depth;
    rig.config.depth_image.max_range_m = 8;  // the wall is 6 m away
    rig.config.depth_image.max_offset = max_offset;
    RigPools pools;
    CameraFrontEnd front(rig.config);
    front.set_observer(&observer);
    DepthSources depth;
    depth.lidar_left_half_only = true;
    depth.T_cam_depth = depth_camera;
    depth.offset_us = offset_us;
    run_still_rig(pools, front, /*with_thermal=*/false, /*with_lidar=*/true, -1, -1, depth);
    return front.figures();
  };
  CountingObserver lidar_only;
  const Duration max_offset = Duration::from_ms(40);
  const CameraFigures without = run(nullptr, 0, max_offset, lidar_only);
  EXPECT_EQ(without.stereo_depth_total, 0u);
  EXPECT_EQ(without.depth_images, 0u);
  // The half the lidar misses has no depth without the depth node.
  EXPECT_GT(lidar_only.right_without_depth, 1000);

  CountingObserver with_depth;
  const CameraFigures with = run(&T_cam_depth, -2000, max_offset, with_depth);
  EXPECT_GT(with.depth_images, 40u);
  EXPECT_GT(with.stereo_depth_total, 1000u);
  EXPECT_EQ(with.stereo_depth_total, static_cast<std::uint64_t>(with_depth.stereo_depths));
  // Every feature has a depth now, the right one, and the lidar's half keeps the lidar's.
  EXPECT_LT(with_depth.right_without_depth, lidar_only.right_without_depth / 20);
  EXPECT_GT(with.depth_total, without.depth_total + 1000);
  EXPECT_LT(with_depth.worst_depth_error_m, 0.02);
  EXPECT_LT(with_depth.stereo_left, with_depth.stereo_depths / 20);

  // A depth image further from every frame than depth_image.max_offset is not used.
  CountingObserver stale;
  const CameraFigures far = run(&T_cam_depth, -20'000, Duration::from_ms(15), stale);
  EXPECT_EQ(far.depth_images, 0u);
  EXPECT_EQ(far.stereo_depth_total, 0u);
}

}  // namespace
}  // namespace posed::fusion
