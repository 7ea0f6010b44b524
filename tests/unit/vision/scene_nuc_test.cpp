// The scene-based NUC against a synthetic microbolometer: a textured scene panning past a fixed
// pattern (per pixel and per column) plus temporal noise. The pattern must be learnt while the
// camera moves, nothing learnt while it holds still, and a reset forgets it.
#include "core/vision/scene_nuc.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

namespace posed::vision {
namespace {

constexpr int kW = 160, kH = 128;

struct Camera {
  cv::Mat world;    // CV_32F scene, wider than the frame so it can pan
  cv::Mat pattern;  // CV_32F fixed offsets of the frame's pixels
  cv::RNG rng{7};

  explicit Camera(double pattern_sigma) {
    world.create(kH, kW * 8, CV_32F);
    rng.fill(world, cv::RNG::NORMAL, 0.0, 1.0);
    cv::GaussianBlur(world, world, cv::Size(0, 0), 1.5);
    cv::normalize(world, world, 60, 190, cv::NORM_MINMAX);
    pattern.create(kH, kW, CV_32F);
    rng.fill(pattern, cv::RNG::NORMAL, 0.0, pattern_sigma);
    cv::Mat column(1, kW, CV_32F);
    rng.fill(column, cv::RNG::NORMAL, 0.0, 0.7 * pattern_sigma);
    for (int y = 0; y < kH; ++y) pattern.row(y) += column;
  }
  /// The scene at pan offset `x` (what a perfect camera would see).
  cv::Mat scene(int x) const { return world(cv::Rect(x, 0, kW, kH)).clone(); }
  /// What the camera sends: scene + pattern + temporal noise, as `type`.
  cv::Mat frame(int x, int type, double scale = 1.0) {
    cv::Mat noise(kH, kW, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
    cv::Mat f = (scene(x) + pattern + noise) * scale, out;
    f.convertTo(out, type);
    return out;
  }
};

/// RMS of what is left of the pattern in `img` (the scene at pan `x` removed, mean removed).
double residual_pattern_rms(const cv::Mat& img, const Camera& cam, int x, double scale = 1.0) {
  cv::Mat f;
  img.convertTo(f, CV_32F, 1.0 / scale);
  cv::Mat r = f - cam.scene(x);
  cv::Scalar mean, stddev;
  cv::meanStdDev(r, mean, stddev);
  return stddev[0];
}

TEST(SceneNuc, LearnsTheFixedPatternWhileTheCameraPans) {
  Camera cam(8.0);
  SceneNucConfig config;
  config.enabled = true;
  SceneNuc nuc(config);
  cv::Mat corrected;
  SceneNucStats stats;
  int x = 0;
  for (int i = 0; i < 300; ++i, x += 3) stats = nuc.correct(cam.frame(x, CV_8UC1), corrected);
  const cv::Mat raw = cam.frame(x, CV_8UC1);
  stats = nuc.correct(raw, corrected);
  const double before = residual_pattern_rms(raw, cam, x);
  const double after = residual_pattern_rms(corrected, cam, x);
  // The pattern is ~10 grey RMS; temporal noise (1 grey) and 8-bit rounding remain.
  EXPECT_GT(before, 9.0);
  EXPECT_LT(after, 0.3 * before) << "before " << before << " after " << after;
  EXPECT_TRUE(stats.updated);
  EXPECT_EQ(stats.updates, 300u);  // every frame but the first (nothing to compare to)
  EXPECT_GT(stats.offset_rms, 0.6 * before);
  EXPECT_EQ(corrected.type(), CV_8UC1);
  EXPECT_EQ(corrected.size(), raw.size());
}

TEST(SceneNuc, WorksOnRawCounts) {
  Camera cam(8.0);
  SceneNucConfig config;
  config.enabled = true;
  SceneNuc nuc(config);
  cv::Mat corrected;
  int x = 0;
  for (int i = 0; i < 300; ++i, x += 3) nuc.correct(cam.frame(x, CV_16UC1, 20.0), corrected);
  const cv::Mat raw = cam.frame(x, CV_16UC1, 20.0);
  nuc.correct(raw, corrected);
  EXPECT_EQ(corrected.type(), CV_16UC1);
  EXPECT_LT(residual_pattern_rms(corrected, cam, x, 20.0),
            0.3 * residual_pattern_rms(raw, cam, x, 20.0));
}

TEST(SceneNuc, LearnsNothingWhileTheCameraHoldsStill) {
  Camera cam(8.0);
  SceneNucConfig config;
  config.enabled = true;
  SceneNuc nuc(config);
  cv::Mat corrected;
  SceneNucStats stats;
  for (int i = 0; i < 200; ++i) {
    const cv::Mat raw = cam.frame(40, CV_8UC1);
    stats = nuc.correct(raw, corrected);
    // The scene held in place would otherwise be learnt as pattern and subtracted.
    ASSERT_EQ(cv::norm(raw, corrected, cv::NORM_INF), 0.0) << "frame " << i;
  }
  EXPECT_FALSE(stats.updated);
  EXPECT_EQ(stats.updates, 0u);
  EXPECT_LT(stats.relative_change, config.min_relative_change);
}

TEST(SceneNuc, ResetForgetsThePattern) {
  Camera cam(8.0);
  SceneNucConfig config;
  config.enabled = true;
  SceneNuc nuc(config);
  cv::Mat corrected;
  int x = 0;
  for (int i = 0; i < 50; ++i, x += 3) nuc.correct(cam.frame(x, CV_8UC1), corrected);
  nuc.reset();
  const cv::Mat raw = cam.frame(x, CV_8UC1);
  const SceneNucStats stats = nuc.correct(raw, corrected);  // first frame: nothing to compare to
  EXPECT_EQ(stats.updates, 0u);
  EXPECT_EQ(cv::norm(raw, corrected, cv::NORM_INF), 0.0);
}

TEST(SceneNuc, RejectsColourFramesAndBadConfig) {
  SceneNucConfig config;
  SceneNuc nuc(config);
  cv::Mat colour(8, 8, CV_8UC3, cv::Scalar::all(0)), out;
  EXPECT_THROW(nuc.correct(colour, out), std::invalid_argument);
  config.average_frames = 0;
  EXPECT_THROW(SceneNuc{config}, std::invalid_argument);
}

}  // namespace
}  // namespace posed::vision
