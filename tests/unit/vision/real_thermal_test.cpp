// The real 16-bit radiometric frame (FLIR Duo Pro R, 640x512, shared/realdata/thermal_16bit)
// through the thermal preprocessing, the quality metrics and the thermal-only front end.
//
// "Sane" here: the frame spans 116 counts (2623..2739, as its exif's Raw Value Range says), so
// the stretch must lie inside that span and be at least min_span_counts wide; the registered
// image must use the 8-bit range (mean in the middle half, spread > 20 grey) with no more than
// the percentile clip saturated; the noise measured on the native pixels, converted back to
// counts, must be that of a microbolometer (0.5..8 counts: temporal noise plus fixed pattern);
// the metrics must be finite and in their ranges, and the tracker must find corners and track
// the same frame onto itself without loss.

#include <gtest/gtest.h>

#include <cstring>
#include <opencv2/core.hpp>

#include "core/vision/image_quality.hpp"
#include "core/vision/thermal_aligner.hpp"
#include "core/vision/visual_frontend.hpp"
#include "tests/common/realdata.hpp"
#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::vision {
namespace {

cv::Mat load_counts(const std::string& path) {
  const std::vector<std::uint8_t> bytes = posed::test::read_bytes(path);
  if (bytes.size() != 640u * 512u * 2u) return {};
  cv::Mat counts(512, 640, CV_16UC1);
  for (std::size_t i = 0; i < 640u * 512u; ++i) {  // little-endian on disk, any host order
    counts.ptr<std::uint16_t>()[i] =
        static_cast<std::uint16_t>(bytes[2 * i] | (bytes[2 * i + 1] << 8));
  }
  return counts;
}

TEST(RealThermalFrame, PreprocessingAndQualityGiveSaneFigures) {
  POSED_REQUIRE_REALDATA(path, "thermal_16bit/frame_000000_640x512_u16le.raw");
  const cv::Mat counts = load_counts(path);
  ASSERT_FALSE(counts.empty());
  double raw_min = 0, raw_max = 0;
  cv::minMaxLoc(counts, &raw_min, &raw_max);
  ASSERT_EQ(raw_max - raw_min, 116);  // the exif's Raw Value Range

  ThermalAligner aligner(scene::m2dgr_visible(), scene::m2dgr_thermal(),
                         scene::m2dgr_T_cam_thermal(), {});
  cv::Mat aligned;
  AlignStats stats;
  ASSERT_TRUE(aligner.align(counts, Eigen::Matrix3d::Identity(), aligned, stats));
  ASSERT_EQ(aligned.size(), cv::Size(640, 480));
  EXPECT_TRUE(stats.normalized);
  EXPECT_EQ(stats.invalid_pixels, 0);
  EXPECT_GE(stats.normalize.low_counts, raw_min);
  EXPECT_LE(stats.normalize.high_counts, raw_max);
  EXPECT_GE(stats.normalize.high_counts - stats.normalize.low_counts, 48);

  cv::Scalar mean, spread;
  cv::meanStdDev(aligned, mean, spread);
  EXPECT_GT(mean[0], 64);
  EXPECT_LT(mean[0], 192);
  EXPECT_GT(spread[0], 20);
  const double saturated =
      (cv::countNonZero(aligned == 0) + cv::countNonZero(aligned == 255)) / (640.0 * 480.0);
  EXPECT_LT(saturated, 0.03);  // 1 % clipped at each end, plus interpolation

  cv::Mat native;
  aligner.native_grey(counts, stats, native);
  QualityAssessor assessor({});
  const ImageQuality q = assessor.assess(native);
  ASSERT_TRUE(q.noise_known);
  const double counts_per_grey = (stats.normalize.high_counts - stats.normalize.low_counts) / 255.0;
  EXPECT_GT(q.noise_sigma * counts_per_grey, 0.5);
  EXPECT_LT(q.noise_sigma * counts_per_grey, 8.0);
  EXPECT_GE(q.gradient_metric, 0.0);
  EXPECT_LE(q.gradient_metric, 1.0);
  EXPECT_GE(q.omega, 1.0);
  EXPECT_GT(q.confidence, 0.0);
  EXPECT_LE(q.confidence, 1.0);
}

TEST(RealThermalFrame, ThermalOnlyFrontEndTracksItOntoItself) {
  POSED_REQUIRE_REALDATA(path, "thermal_16bit/frame_000000_640x512_u16le.raw");
  const cv::Mat counts = load_counts(path);
  ASSERT_FALSE(counts.empty());
  FrontendConfig config;
  config.mode = FrontendMode::kThermal;
  config.visible_camera = scene::m2dgr_visible();
  config.thermal_camera = scene::m2dgr_thermal();
  config.T_cam_thermal = scene::m2dgr_T_cam_thermal();
  VisualFrontend frontend(config);
  FrontendInput input;
  input.thermal = counts;
  FrontendFrame first, second;
  input.thermal_stamp = HostTime::from_ns(1'000'000'000);
  ASSERT_EQ(frontend.process(input, first), FrontendStatus::kOk);
  input.thermal_stamp = HostTime::from_ns(1'040'000'000);
  ASSERT_EQ(frontend.process(input, second), FrontendStatus::kOk);
  EXPECT_GT(first.counts.features, 50);
  EXPECT_TRUE(first.quality.thermal.valid);
  EXPECT_FALSE(first.quality.visible.valid);
  EXPECT_FALSE(first.quality.fused.valid);
  // The same frame again: every feature is tracked in place, none is lost to RANSAC.
  EXPECT_EQ(second.counts.previous, first.counts.features);
  EXPECT_EQ(second.counts.tracked, first.counts.features);
  EXPECT_EQ(second.counts.ransac_inliers, first.counts.features);
  ASSERT_GE(second.features.size(), first.features.size());  // topped up with new ones
  int moved = 0;
  for (std::size_t i = 0; i < first.features.size(); ++i) {
    ASSERT_EQ(second.features[i].id, first.features[i].id);
    ASSERT_EQ(second.features[i].track_length, 2u);
    moved += (second.features[i].pixel_px - first.features[i].pixel_px).norm() > 0.05f ? 1 : 0;
  }
  EXPECT_EQ(moved, 0);
}

}  // namespace
}  // namespace posed::vision
