// The fusion rules of seed 000 on synthetic bands (eq. 7: low bands averaged; eq. 8: detail
// coefficients by absolute maximum, sign kept) and the whole fusion on images whose content is
// known: identical inputs come back unchanged, and each input's edges survive in the fusion.

#include "core/vision/dwt_fusion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/vision/image_quality.hpp"
#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::vision {
namespace {

TEST(FusionRules, LowBandIsTheAverage) {
  const cv::Mat v = (cv::Mat_<float>(1, 4) << 10, -4, 200, 0);
  const cv::Mat t = (cv::Mat_<float>(1, 4) << 30, 4, 100, 0);
  cv::Mat out;
  fuse_low_band(v, t, 0.5, out);
  EXPECT_FLOAT_EQ(out.at<float>(0), 20.f);
  EXPECT_FLOAT_EQ(out.at<float>(1), 0.f);
  EXPECT_FLOAT_EQ(out.at<float>(2), 150.f);
  EXPECT_FLOAT_EQ(out.at<float>(3), 0.f);
  fuse_low_band(v, t, 0.25, out);  // weighted variant
  EXPECT_FLOAT_EQ(out.at<float>(0), 15.f);
}

TEST(FusionRules, HighBandTakesTheLargerMagnitudeWithItsSign) {
  const cv::Mat v = (cv::Mat_<float>(1, 6) << 5, -9, 3, -3, 0, 7);
  const cv::Mat t = (cv::Mat_<float>(1, 6) << -8, 2, -3, 3, -0.5f, 7);
  cv::Mat out;
  fuse_high_band(v, t, out);
  EXPECT_FLOAT_EQ(out.at<float>(0), -8.f);   // thermal larger, negative sign kept
  EXPECT_FLOAT_EQ(out.at<float>(1), -9.f);   // visible larger
  EXPECT_FLOAT_EQ(out.at<float>(2), 3.f);    // tie: visible
  EXPECT_FLOAT_EQ(out.at<float>(3), -3.f);   // tie: visible
  EXPECT_FLOAT_EQ(out.at<float>(4), -0.5f);  // thermal larger
  EXPECT_FLOAT_EQ(out.at<float>(5), 7.f);
}

TEST(FusionRules, HighBandMayWriteIntoAnInput) {
  cv::Mat v = (cv::Mat_<float>(1, 3) << 1, -6, 2);
  const cv::Mat t = (cv::Mat_<float>(1, 3) << -4, 5, 1);
  fuse_high_band(v, t, v);
  EXPECT_FLOAT_EQ(v.at<float>(0), -4.f);
  EXPECT_FLOAT_EQ(v.at<float>(1), -6.f);
  EXPECT_FLOAT_EQ(v.at<float>(2), 2.f);
}

TEST(FusionRules, NoiseAwareHighBandComparesSignificance) {
  // Visible noise sigma 6, thermal 1, signal above 3 sigma.
  const cv::Mat v = (cv::Mat_<float>(1, 5) << 6, -3, 30, 24, 40);
  const cv::Mat t = (cv::Mat_<float>(1, 5) << 2, -2, 4, 0.5f, -9);
  cv::Mat out;
  fuse_high_band_noise_aware(v, t, 6.0, 1.0, 3.0, out);
  EXPECT_FLOAT_EQ(out.at<float>(0), 2.f);   // neither is signal: the quieter (thermal) image
  EXPECT_FLOAT_EQ(out.at<float>(1), -2.f);  // neither is signal
  EXPECT_FLOAT_EQ(out.at<float>(2), 30.f);  // 5 sigma of visible beats 4 of thermal
  EXPECT_FLOAT_EQ(out.at<float>(3), 24.f);  // 4 sigma of visible against 0.5: visible
  EXPECT_FLOAT_EQ(out.at<float>(4), -9.f);  // 9 sigma of thermal beats 6.7 of visible
}

TEST(DwtFusion, NoiseAwareRuleKeepsTheQuieterImageInFlatRegions) {
  // Both see a flat wall; the visible image is 8x noisier. Eq. (8) takes the larger coefficient,
  // i.e. the visible noise; the noise-aware rule takes the quiet thermal detail.
  const cv::Mat flat(240, 320, CV_8UC1, cv::Scalar(100));
  const cv::Mat visible = scene::add_noise(flat, 8.0, 1), thermal = scene::add_noise(flat, 1.0, 2);
  const auto noise_of = [&](const FusionConfig& config) {
    DwtFusion fusion(config);
    cv::Mat fused;
    fusion.fuse(visible, thermal, fused, 8.0, 1.0);
    cv::Scalar mean, sd;
    cv::meanStdDev(fused, mean, sd);
    return sd[0];
  };
  for (const Wavelet w : {Wavelet::kHaar, Wavelet::kLeGall53, Wavelet::kCdf97}) {
    FusionConfig published, aware;
    published.wavelet = aware.wavelet = w;
    published.noise_weighted = false;
    const double literal = noise_of(published), weighted = noise_of(aware);
    EXPECT_GT(literal, 5.0) << to_string(w);  // the detail bands are the visible noise
    // What is left: the averaged low band keeps half of the visible image's coarse noise (the
    // 2-level low-pass of sigma 8: 2 grey for Haar's block mean, 4 for 5/3), the few visible
    // coefficients above 3 sigma, and the thermal noise.
    EXPECT_LT(weighted, 3.5) << to_string(w);
    EXPECT_LT(weighted, 0.45 * literal) << to_string(w);
  }
}

TEST(DwtFusion, IdenticalInputsComeBackUnchanged) {
  const cv::Mat image = scene::texture_image(640, 480, 0.01, 200, 20, 3);
  for (const Wavelet w : {Wavelet::kHaar, Wavelet::kLeGall53, Wavelet::kCdf97}) {
    FusionConfig config;
    config.wavelet = w;
    DwtFusion fusion(config);
    cv::Mat fused;
    fusion.fuse(image, image, fused);
    EXPECT_LE(cv::norm(fused, image, cv::NORM_INF), 1.0) << to_string(w);  // rounding only
  }
}

TEST(DwtFusion, OddSizesArePaddedAndCroppedBack) {
  const cv::Mat image = scene::texture_image(37, 29, 0.02, 200, 20, 4);
  DwtFusion fusion({});
  cv::Mat fused;
  fusion.fuse(image, image, fused);
  ASSERT_EQ(fused.size(), image.size());
  EXPECT_LE(cv::norm(fused, image, cv::NORM_INF), 1.0);
}

TEST(DwtFusion, KeepsTheFineDetailOfBothImagesAndAveragesTheCoarse) {
  // Visible: fine checkerboard (2 px cells) on the left and a large bright square; thermal: fine
  // stripes (2 px) on the right and a large warm disc; both flat elsewhere.
  cv::Mat visible(128, 128, CV_8UC1, cv::Scalar(60));
  cv::Mat thermal(128, 128, CV_8UC1, cv::Scalar(100));
  for (int r = 8; r < 40; ++r)
    for (int c = 8; c < 40; ++c) visible.at<std::uint8_t>(r, c) = ((r / 2 + c / 2) % 2) ? 120 : 0;
  for (int r = 8; r < 40; ++r)
    for (int c = 88; c < 120; ++c) thermal.at<std::uint8_t>(r, c) = (c / 2) % 2 ? 180 : 20;
  visible(cv::Rect(16, 64, 40, 40)).setTo(200);
  cv::circle(thermal, cv::Point(96, 84), 18, cv::Scalar(240), cv::FILLED);
  DwtFusion fusion({});
  cv::Mat fused;
  fusion.fuse(visible, thermal, fused);

  // Fine detail lives in the detail bands, where the other image is flat: eq. (8) keeps it whole.
  const auto stddev = [](const cv::Mat& m) {
    cv::Scalar mean, sd;
    cv::meanStdDev(m, mean, sd);
    return sd[0];
  };
  const cv::Rect checker(12, 12, 24, 24), stripes(92, 12, 24, 24);
  EXPECT_GT(stddev(fused(checker)), 0.95 * stddev(visible(checker)));
  EXPECT_GT(stddev(fused(stripes)), 0.95 * stddev(thermal(stripes)));
  // A structure larger than the 4-pixel scale of two levels is mostly low band: averaged by
  // eq. (7), so its contrast is halved: the square's 140 becomes 70, the disc's 140 too.
  const double square_step =
      cv::mean(fused(cv::Rect(26, 74, 20, 20)))[0] - cv::mean(fused(cv::Rect(16, 112, 20, 10)))[0];
  const double disc_step =
      cv::mean(fused(cv::Rect(90, 78, 12, 12)))[0] - cv::mean(fused(cv::Rect(70, 112, 12, 10)))[0];
  EXPECT_NEAR(square_step, 70.0, 5.0);
  EXPECT_NEAR(disc_step, 70.0, 5.0);
  // A flat patch away from everything is the low bands' average: (60 + 100) / 2.
  EXPECT_NEAR(cv::mean(fused(cv::Rect(56, 2, 20, 4)))[0], 80.0, 2.0);
}

/// A vertical step from 60 to 160 grey at column 320 (640x480).
cv::Mat step_image() {
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(60));
  image(cv::Rect(320, 0, 320, 480)).setTo(160);
  return image;
}

TEST(DenoiseGaussian, BringsTheNoiseDownToTheTargetAndKeepsTheEdge) {
  const double sigma = 15.0, target = 2.0;
  const cv::Mat clean = step_image();
  const cv::Mat noisy = scene::add_noise(clean, sigma, 7);
  cv::Mat denoised, denoised_clean;
  const double residual = denoise_gaussian(noisy, sigma, target, 3.0, denoised);
  EXPECT_NEAR(residual, target, 0.1);  // sigma 15 / (2 sqrt(pi) 2) = 2.1 px is within the cap
  // The noise actually left: the smoothed noisy image against the smoothed clean one, in flat
  // regions (the filter is linear; rounding adds 0.29 grey).
  denoise_gaussian(clean, sigma, target, 3.0, denoised_clean);
  cv::Mat diff;
  cv::subtract(denoised, denoised_clean, diff, cv::noArray(), CV_32F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(diff(cv::Rect(20, 20, 280, 440)), mean, stddev);
  EXPECT_NEAR(stddev[0], residual, 0.25 * residual);
  // The quality module's noise metric sees it too.
  QualityAssessor quality{QualityConfig{}};
  const double before = quality.assess(noisy).noise_sigma;
  const double after = quality.assess(denoised).noise_sigma;
  EXPECT_GT(before, 12.0);
  EXPECT_LT(after, 0.35 * before);
  // The edge stays where it was, and steep: 4 px either side (~2 sigma of the kernel) the
  // row-averaged profile is within 5 % of the contrast of each side's level.
  cv::Mat profile;
  cv::reduce(denoised, profile, 0, cv::REDUCE_AVG, CV_64F);
  EXPECT_LT(profile.at<double>(0, 315), 65.0);
  EXPECT_GT(profile.at<double>(0, 324), 155.0);
  EXPECT_NEAR(profile.at<double>(0, 319) + profile.at<double>(0, 320), 220.0, 6.0);
}

TEST(DenoiseGaussian, QuietOrUnknownImagesPassUntouched) {
  const cv::Mat image = scene::add_noise(step_image(), 1.5, 3);
  cv::Mat out;
  EXPECT_EQ(denoise_gaussian(image, 1.5, 2.0, 3.0, out), 1.5);
  EXPECT_EQ(out.data, image.data);  // a view, no copy
  EXPECT_EQ(denoise_gaussian(image, 0.0, 2.0, 3.0, out), 0.0);
  EXPECT_EQ(out.data, image.data);
}

TEST(DenoiseGaussian, TheKernelIsCappedAndTheResidualSaysSo) {
  // Sigma 30 would need a 4.2 px kernel to reach 2 grey; capped at 1 px it leaves 30 x 0.28.
  const cv::Mat clean(480, 640, CV_8UC1, cv::Scalar(128));
  const cv::Mat noisy = scene::add_noise(clean, 30.0, 5);
  cv::Mat out;
  const double residual = denoise_gaussian(noisy, 30.0, 2.0, 1.0, out);
  EXPECT_NEAR(residual, 30.0 / (2.0 * std::sqrt(std::numbers::pi)), 0.5);
  cv::Scalar mean, stddev;
  cv::meanStdDev(out, mean, stddev);
  EXPECT_NEAR(stddev[0], residual, 0.2 * residual);
}

}  // namespace
}  // namespace posed::vision
