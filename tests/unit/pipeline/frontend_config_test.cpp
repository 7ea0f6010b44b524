// The camera front end's configuration as the daemon builds it from posed.yaml: the tracker's
// thresholds are the configured ones, and the schema's defaults are the tracker's own.

#include "daemon/pipeline/frontend_config.hpp"

#include <gtest/gtest.h>

#include <string>

#include "core/vision/feature_tracker.hpp"
#include "daemon/config/config_loader.hpp"

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

}  // namespace
}  // namespace posed::pipeline
