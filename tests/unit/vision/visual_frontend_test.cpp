// The composed front end on a rendered drive past a wall: a dark, noisy colour camera and a
// thermal camera with its own texture, both through the M2DGR lenses and extrinsics, and lidar
// points on the wall. Checks every mode's output (ids, lengths, depths, qualities, counts), that
// fusion rescues the dark visible image, determinism, the probe, and bad input.

#include "core/vision/visual_frontend.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::vision {
namespace {

constexpr double kWallDepthM = 6.0;
constexpr int kFrames = 5;
constexpr double kStepM = 0.04;  // sideways per frame: ~4 px of image motion

struct Drive {
  std::vector<cv::Mat> visible;        // BGR, dark and noisy
  std::vector<cv::Mat> thermal;        // 8-bit, its own texture
  std::vector<Eigen::Vector3f> lidar;  // the wall in the camera frame (same for every frame)
};

const Drive& drive() {
  static const Drive rendered = [] {
    Drive out;
    const auto visible_rays = scene::pixel_rays(scene::m2dgr_visible());
    const auto thermal_rays = scene::pixel_rays(scene::m2dgr_thermal());
    for (int k = 0; k < kFrames; ++k) {
      Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
      T_world_cam.translation().x() = kStepM * k;
      // Night: the visible texture spans 14 grey levels over a floor of 4, noise 2.
      const cv::Mat grey = scene::add_noise(scene::render_wall(scene::m2dgr_visible(), visible_rays,
                                                               T_world_cam, kWallDepthM, 14, 4, 1),
                                            2.0, 100 + static_cast<std::uint64_t>(k));
      cv::Mat bgr;
      cv::merge(std::vector<cv::Mat>{grey, grey, grey}, bgr);
      out.visible.push_back(bgr);
      out.thermal.push_back(scene::add_noise(
          scene::render_wall(scene::m2dgr_thermal(), thermal_rays,
                             T_world_cam * scene::m2dgr_T_cam_thermal(), kWallDepthM, 180, 40, 77),
          1.5, 200 + static_cast<std::uint64_t>(k)));
    }
    // A 32-ring sweep of the wall, 0.2 deg apart along the rings.
    for (int ring = 0; ring < 32; ++ring) {
      const double elevation = (-25.0 + 40.0 * ring / 31.0) * std::numbers::pi / 180.0;
      for (double az = -40; az <= 40; az += 0.2) {
        const double a = az * std::numbers::pi / 180.0;
        const Eigen::Vector3d d(std::cos(elevation) * std::sin(a), -std::sin(elevation),
                                std::cos(elevation) * std::cos(a));
        out.lidar.push_back((kWallDepthM / d.z() * d).cast<float>());
      }
    }
    return out;
  }();
  return rendered;
}

FrontendConfig config_for(FrontendMode mode) {
  FrontendConfig c;
  c.mode = mode;
  c.visible_camera = scene::m2dgr_visible();
  c.thermal_camera = scene::m2dgr_thermal();
  c.T_cam_thermal = scene::m2dgr_T_cam_thermal();
  c.thermal_align.mode = AlignMode::kPlane;  // the wall's depth is known here
  c.thermal_align.plane_depth_m = kWallDepthM;
  return c;
}

FrontendInput input_for(int k) {
  FrontendInput in;
  in.visible_stamp = HostTime::from_ns(1'000'000'000 + k * 66'666'667LL);
  in.thermal_stamp = in.visible_stamp - Duration::from_ms(5);
  in.visible = drive().visible[static_cast<std::size_t>(k)];
  in.thermal = drive().thermal[static_cast<std::size_t>(k)];
  in.p_cam_m = drive().lidar;
  return in;
}

std::vector<FrontendFrame> run(FrontendMode mode) {
  VisualFrontend frontend(config_for(mode));
  std::vector<FrontendFrame> frames(kFrames);
  for (int k = 0; k < kFrames; ++k) {
    EXPECT_EQ(frontend.process(input_for(k), frames[static_cast<std::size_t>(k)]),
              FrontendStatus::kOk);
  }
  return frames;
}

TEST(VisualFrontend, EveryModeTracksWithStableIdsAndLidarDepth) {
  for (const FrontendMode mode :
       {FrontendMode::kVisible, FrontendMode::kThermal, FrontendMode::kFused}) {
    SCOPED_TRACE(to_string(mode));
    const std::vector<FrontendFrame> frames = run(mode);
    for (int k = 0; k < kFrames; ++k) {
      const FrontendFrame& f = frames[static_cast<std::size_t>(k)];
      EXPECT_EQ(f.mode, mode);
      EXPECT_EQ(f.stamp, mode == FrontendMode::kThermal ? input_for(k).thermal_stamp
                                                        : input_for(k).visible_stamp);
      EXPECT_EQ(f.counts.features, static_cast<int>(f.features.size()));
      EXPECT_LE(f.counts.features, 300);
      EXPECT_EQ(f.quality.visible.valid, mode != FrontendMode::kThermal);
      EXPECT_EQ(f.quality.thermal.valid, mode != FrontendMode::kVisible);
      EXPECT_EQ(f.quality.fused.valid, mode == FrontendMode::kFused);
      EXPECT_GT(f.counts.lidar_points, 1000);
      int depth_ok = 0;
      for (const FrontendFeature& feature : f.features) {
        if (feature.depth_status != DepthStatus::kOk) continue;
        ++depth_ok;
        EXPECT_NEAR(feature.depth_m, kWallDepthM, 1e-3);  // the wall is the plane z = 6 m
      }
      EXPECT_EQ(depth_ok, f.counts.depth_associated);
      if (k == 0) continue;
      // Ids carry over: every feature of the previous frame that is still there has grown by
      // one frame, and moved like the wall (~4 px to the left).
      const FrontendFrame& before = frames[static_cast<std::size_t>(k - 1)];
      int carried = 0;
      for (const FrontendFeature& feature : f.features) {
        for (const FrontendFeature& old : before.features) {
          if (old.id != feature.id) continue;
          ++carried;
          EXPECT_EQ(feature.track_length, old.track_length + 1);
          EXPECT_LT(feature.pixel_px.x(), old.pixel_px.x());
          // Velocity: change of normalised coordinates over the 66.7 ms between the frames.
          EXPECT_NEAR(feature.velocity_per_s.x(),
                      (feature.normalised.x() - old.normalised.x()) / 0.0666666670, 1e-6);
        }
      }
      EXPECT_EQ(carried, f.counts.ransac_inliers - f.counts.crowded);
      EXPECT_LT(f.counts.crowded, 0.05 * f.counts.ransac_inliers);
    }
  }
}

TEST(VisualFrontend, FusionRescuesTheDarkVisibleImage) {
  // The paper's Table 2 comparison on this drive: the night-time visible image alone keeps few
  // tracks, the fusion keeps at least as many as the better stream and matches as well.
  const auto visible = run(FrontendMode::kVisible);
  const auto fused = run(FrontendMode::kFused);
  double visible_tracked = 0, fused_tracked = 0;
  for (int k = 1; k < kFrames; ++k) {
    visible_tracked += visible[static_cast<std::size_t>(k)].counts.ransac_inliers;
    fused_tracked += fused[static_cast<std::size_t>(k)].counts.ransac_inliers;
  }
  EXPECT_GT(fused_tracked, 1.2 * visible_tracked);
  // The fusion is judged better than the dark visible image.
  EXPECT_GT(fused.back().quality.fused.confidence, fused.back().quality.visible.confidence);
}

TEST(VisualFrontend, IsDeterministic) {
  const auto a = run(FrontendMode::kFused);
  const auto b = run(FrontendMode::kFused);
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].features.size(), b[k].features.size());
    for (std::size_t i = 0; i < a[k].features.size(); ++i) {
      EXPECT_EQ(a[k].features[i].id, b[k].features[i].id);
      EXPECT_EQ(a[k].features[i].pixel_px, b[k].features[i].pixel_px);
      EXPECT_TRUE(a[k].features[i].depth_m == b[k].features[i].depth_m ||
                  (std::isnan(a[k].features[i].depth_m) && std::isnan(b[k].features[i].depth_m)));
    }
    EXPECT_EQ(a[k].quality.fused.noise_sigma, b[k].quality.fused.noise_sigma);
  }
}

class RecordingProbe final : public FrontendStepProbe {
 public:
  void begin(FrontendStep step) override { events.emplace_back(step, true); }
  void end(FrontendStep step) override { events.emplace_back(step, false); }
  std::vector<std::pair<FrontendStep, bool>> events;
};

TEST(VisualFrontend, ProbeSeesEveryStepInOrder) {
  VisualFrontend frontend(config_for(FrontendMode::kFused));
  RecordingProbe probe;
  frontend.set_probe(&probe);
  FrontendFrame frame;
  ASSERT_EQ(frontend.process(input_for(0), frame), FrontendStatus::kOk);
  std::vector<std::pair<FrontendStep, bool>> expected;
  // Quality of the input streams before the fusion (its noise-aware rule needs their noise),
  // of the fusion after it.
  for (const FrontendStep s :
       {FrontendStep::kEnhance, FrontendStep::kThermal, FrontendStep::kQuality,
        FrontendStep::kFusion, FrontendStep::kQuality, FrontendStep::kTracking,
        FrontendStep::kDepth}) {
    expected.emplace_back(s, true);
    expected.emplace_back(s, false);
  }
  EXPECT_EQ(probe.events, expected);
}

TEST(VisualFrontend, ReportsUnusableInput) {
  VisualFrontend fused(config_for(FrontendMode::kFused));
  FrontendFrame frame;
  FrontendInput in = input_for(0);
  in.visible = cv::Mat(240, 320, CV_8UC3, cv::Scalar(0));
  EXPECT_EQ(fused.process(in, frame), FrontendStatus::kVisibleUnusable);
  in = input_for(0);
  in.thermal = cv::Mat();
  EXPECT_EQ(fused.process(in, frame), FrontendStatus::kThermalUnusable);
  in.thermal = cv::Mat(100, 100, CV_8UC1, cv::Scalar(0));
  EXPECT_EQ(fused.process(in, frame), FrontendStatus::kThermalUnusable);
  // Visible-only mode never looks at the thermal frame.
  VisualFrontend visible(config_for(FrontendMode::kVisible));
  EXPECT_EQ(visible.process(in, frame), FrontendStatus::kOk);
}

TEST(VisualFrontend, RefusesMissingIntrinsics) {
  FrontendConfig config = config_for(FrontendMode::kFused);
  config.thermal_camera = {};
  EXPECT_THROW(VisualFrontend{config}, std::invalid_argument);
  config.mode = FrontendMode::kVisible;  // does not need the thermal camera
  EXPECT_NO_THROW(VisualFrontend{config});
  config.visible_camera.fx = 0;
  EXPECT_THROW(VisualFrontend{config}, std::invalid_argument);
}

TEST(VisualFrontend, ThermalEnhancementNeverWritesIntoTheInput) {
  FrontendConfig config = config_for(FrontendMode::kThermal);
  config.thermal_enhance.enabled = true;
  VisualFrontend frontend(config);
  FrontendInput in = input_for(0);
  const cv::Mat before = in.thermal.clone();
  FrontendFrame frame;
  ASSERT_EQ(frontend.process(in, frame), FrontendStatus::kOk);
  EXPECT_EQ(cv::norm(in.thermal, before, cv::NORM_INF), 0.0);
  EXPECT_TRUE(frame.quality.thermal.valid);
}

TEST(VisualFrontend, ThermalNucLearnsWhileMovingAndForgetsAtTheShutter) {
  FrontendConfig c = config_for(FrontendMode::kThermal);
  c.thermal_nuc.enabled = true;
  VisualFrontend frontend(c);
  FrontendFrame frame;
  const cv::Mat before = drive().thermal[0].clone();
  for (int k = 0; k < kFrames; ++k) {
    ASSERT_EQ(frontend.process(input_for(k), frame), FrontendStatus::kOk);
    // The first frame has nothing to compare with; each later one moved ~4 px.
    EXPECT_EQ(frame.thermal_nuc.updates, static_cast<std::uint64_t>(k)) << "frame " << k;
  }
  EXPECT_GT(frame.thermal_nuc.offset_rms, 0.0);
  EXPECT_EQ(cv::norm(before, drive().thermal[0], cv::NORM_INF), 0.0);  // input untouched
  frontend.thermal_shutter();
  ASSERT_EQ(frontend.process(input_for(0), frame), FrontendStatus::kOk);
  EXPECT_EQ(frame.thermal_nuc.updates, 0u);
  // Off (the default): nothing is learnt.
  VisualFrontend plain(config_for(FrontendMode::kThermal));
  ASSERT_EQ(plain.process(input_for(0), frame), FrontendStatus::kOk);
  ASSERT_EQ(plain.process(input_for(1), frame), FrontendStatus::kOk);
  EXPECT_EQ(frame.thermal_nuc.updates, 0u);
}

TEST(VisualFrontend, WrapsCoreImagesWithoutCopying) {
  PayloadPool pool(2, (640 * 3 + 16) * 480);
  Image image;
  image.width = 640;
  image.height = 480;
  image.stride = 640 * 3 + 16;  // padded rows
  image.format = PixelFormat::kRgb8;
  image.stamp = HostTime::from_ns(42);
  image.pixels = pool.acquire();
  const FrontendInput in = make_input(&image, nullptr);
  EXPECT_EQ(in.visible.data, reinterpret_cast<const std::uint8_t*>(image.pixels.bytes().data()));
  EXPECT_EQ(in.visible.step, static_cast<std::size_t>(640 * 3 + 16));
  EXPECT_TRUE(in.visible_rgb);
  EXPECT_EQ(in.visible_stamp, image.stamp);
  EXPECT_TRUE(in.thermal.empty());
  image.stride = 100;  // shorter than a row: refused, not read out of bounds
  EXPECT_TRUE(make_input(&image, nullptr).visible.empty());
}

}  // namespace
}  // namespace posed::vision
