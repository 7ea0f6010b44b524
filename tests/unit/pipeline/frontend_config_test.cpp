// The camera front end's configuration as the daemon builds it from posed.yaml: the tracker's
// thresholds are the configured ones, and the schema's defaults are the tracker's own.

#include "daemon/pipeline/frontend_config.hpp"

#include <gtest/gtest.h>

#include <string>

#include "core/vision/feature_tracker.hpp"
#include "daemon/config/config_loader.hpp"
#include "daemon/pipeline/estimator_config.hpp"

namespace posed::pipeline {
namespace {

fusion::CameraFrontEndConfig front_end_of(const std::string& yaml) {
  const config::LoadResult loaded = config::load_config_text(yaml, "test.yaml");
  EXPECT_TRUE(loaded.ok()) << loaded.error_text();
  std::string note;
  return camera_front_end_config(loaded.config, true, true, true, note);
}

TEST(FrontendConfig, TheTrackersThresholdsAreTheConfiguredOnes) {
  const fusion::CameraFrontEndConfig c =
      front_end_of("frontend:\n  forward_backward_px: 1.5\n  ransac_threshold_px: 2.5\n");
  EXPECT_DOUBLE_EQ(c.frontend.tracker.max_forward_backward_px, 1.5);
  EXPECT_DOUBLE_EQ(c.frontend.tracker.ransac_threshold_px, 2.5);
}

TEST(FrontendConfig, TheForwardBackwardDefaultIsTheTrackersOwn) {
  const fusion::CameraFrontEndConfig c = front_end_of("");
  EXPECT_DOUBLE_EQ(c.frontend.tracker.max_forward_backward_px,
                   vision::TrackerConfig{}.max_forward_backward_px);
}

TEST(FrontendConfig, TheKltWindowAndPyramidAreTheConfiguredOnesAndDefaultToTheTrackers) {
  const fusion::CameraFrontEndConfig c =
      front_end_of("frontend:\n  klt_window_px: 21\n  klt_pyramid_levels: 4\n");
  EXPECT_EQ(c.frontend.tracker.klt_window_px, 21);
  EXPECT_EQ(c.frontend.tracker.klt_pyramid_levels, 4);
  const fusion::CameraFrontEndConfig d = front_end_of("");
  EXPECT_EQ(d.frontend.tracker.klt_window_px, vision::TrackerConfig{}.klt_window_px);
  EXPECT_EQ(d.frontend.tracker.klt_pyramid_levels, vision::TrackerConfig{}.klt_pyramid_levels);
}

TEST(FrontendConfig, TheDepthNodeReachesTheFeaturesOnlyWhenAskedAndAtItsExtrinsic) {
  // Off by default: a recording's depth stream is then not even replayed (run_daemon).
  EXPECT_FALSE(config::default_config().depth_camera.feature_depth);
  const fusion::CameraFrontEndConfig c = front_end_of(
      "depth_camera:\n  feature_depth: true\n  fx: 400\n  cx: 320\n  feature_stride_px: 8\n"
      "  feature_max_range_m: 3\n  feature_max_span_m: 0.2\n  feature_max_offset_s: 0.02\n"
      "extrinsics:\n  T_cam_depth: [1, 0, 0, 0.015, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n");
  EXPECT_TRUE(c.depth_image.enabled);
  EXPECT_DOUBLE_EQ(c.depth_image.fx, 400);
  EXPECT_DOUBLE_EQ(c.depth_image.cx, 320);
  EXPECT_EQ(c.depth_image.stride_px, 8);
  EXPECT_DOUBLE_EQ(c.depth_image.max_range_m, 3);
  EXPECT_EQ(c.depth_image.max_offset.ns, 20'000'000);
  EXPECT_DOUBLE_EQ(c.depth_image.T_cam_depth.translation().x(), 0.015);
  // The depth search over the image's points: its span and range are the depth node's keys.
  EXPECT_DOUBLE_EQ(c.frontend.stereo_depth.max_span_m, 0.2);
  EXPECT_DOUBLE_EQ(c.frontend.stereo_depth.max_range_m, 3);
  EXPECT_FALSE(front_end_of("").depth_image.enabled);
}

fusion::CameraFactorsConfig factors_of(const std::string& yaml) {
  const config::LoadResult loaded = config::load_config_text(yaml, "test.yaml");
  EXPECT_TRUE(loaded.ok()) << loaded.error_text();
  std::string note;
  const fusion::CameraFrontEndConfig cameras =
      camera_front_end_config(loaded.config, true, true, true, note);
  return camera_factors_config(loaded.config, cameras);
}

TEST(FrontendConfig, TheCameraCouplingAndTheLandmarksThresholdsAreTheConfiguredOnes) {
  EXPECT_EQ(factors_of("").coupling, fusion::CameraCoupling::kBetween);
  const fusion::CameraFactorsConfig l = factors_of(
      "estimator:\n  camera_coupling: landmarks\n  camera_landmark_huber_sigma: 2.5\n"
      "  camera_landmark_gate_px: 12\n  camera_landmark_outlier_sigma: 8\n");
  EXPECT_EQ(l.coupling, fusion::CameraCoupling::kLandmarks);
  EXPECT_TRUE(l.streams[0]);
  EXPECT_DOUBLE_EQ(l.landmarks.huber_sigma, 2.5);
  EXPECT_DOUBLE_EQ(l.landmarks.gate_px, 12);
  EXPECT_DOUBLE_EQ(l.landmarks.outlier_sigma, 8);
  // The frame pairs' gates about the prediction: 3 px, and 6 px where the lidar is weak.
  EXPECT_DOUBLE_EQ(factors_of("").guess_gate_px, 3);
  EXPECT_DOUBLE_EQ(factors_of("").weak_lidar_guess_gate_px, 6);
  const fusion::CameraFactorsConfig g =
      factors_of("estimator:\n  camera_guess_gate_px: 2.5\n  camera_weak_lidar_guess_gate_px: 9\n");
  EXPECT_DOUBLE_EQ(g.guess_gate_px, 2.5);
  EXPECT_DOUBLE_EQ(g.weak_lidar_guess_gate_px, 9);
  // The translation floor: 2 mm by default wherever the lidar is, and its own key where the
  // lidar pins the motion.
  EXPECT_DOUBLE_EQ(factors_of("").floor_translation_m, 0.002);
  EXPECT_DOUBLE_EQ(factors_of("").strong_lidar_floor_translation_m, 0.002);
  EXPECT_DOUBLE_EQ(factors_of("estimator:\n  camera_strong_lidar_floor_translation_m: 0.01\n")
                       .strong_lidar_floor_translation_m,
                   0.01);
  // ... which applies once the lidar has pinned everything for camera_strong_lidar_after_s.
  const auto settled_after_s = [](const std::string& yaml) {
    const config::LoadResult loaded = config::load_config_text(yaml, "test.yaml");
    EXPECT_TRUE(loaded.ok()) << loaded.error_text();
    return lio_config(loaded.config).aided_settled_after_s;
  };
  EXPECT_DOUBLE_EQ(settled_after_s(""), 5);
  EXPECT_DOUBLE_EQ(settled_after_s("estimator:\n  camera_strong_lidar_after_s: 12\n"), 12);
  EXPECT_EQ(factors_of("estimator:\n  camera_coupling: loose+landmarks\n").coupling,
            fusion::CameraCoupling::kBoth);
  // A coupling the schema does not know stops start-up, naming the key.
  const config::LoadResult bad =
      config::load_config_text("estimator:\n  camera_coupling: tight\n", "test.yaml");
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.error_text().find("estimator.camera_coupling"), std::string::npos)
      << bad.error_text();
}

}  // namespace
}  // namespace posed::pipeline
