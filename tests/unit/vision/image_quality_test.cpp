// Seed 002's image quality: the gradient metric rises with texture and falls with darkness, the
// noise metric tracks the noise actually added (Immerkaer's estimator on the homogeneous,
// unsaturated pixels), and the confidence follows: up with texture, down with noise and darkness.

#include "core/vision/image_quality.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::vision {
namespace {

/// A scene with `texture` (0 = flat grey, 1 = full wall texture) around mid-grey.
cv::Mat textured(double texture, double brightness = 1.0) {
  const cv::Mat t = scene::texture_image(640, 480, 0.01, 200 * texture * brightness,
                                         (128 - 100 * texture) * brightness, 31);
  return t;
}

TEST(ImageQuality, GradientMetricAndConfidenceRiseWithTexture) {
  QualityAssessor assessor({});
  double previous_g = -1, previous_confidence = -1;
  for (const double texture : {0.1, 0.2, 0.3, 0.5, 1.0}) {
    const ImageQuality q = assessor.assess(scene::add_noise(textured(texture), 2.0, 1));
    EXPECT_GT(q.gradient_metric, previous_g) << texture;
    EXPECT_GT(q.confidence, previous_confidence) << texture;
    previous_g = q.gradient_metric;
    previous_confidence = q.confidence;
  }
  EXPECT_GT(previous_g, 0.3);
}

TEST(ImageQuality, NoiseMetricMeasuresTheAddedNoise) {
  QualityAssessor assessor({});
  // Smooth content (a gentle ramp): Immerkaer's mask cancels it, so sigma_n is the noise alone.
  cv::Mat ramp(480, 640, CV_8UC1);
  for (int r = 0; r < 480; ++r)
    for (int c = 0; c < 640; ++c)
      ramp.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(60 + c / 5);
  for (const double sigma : {1.0, 3.0, 6.0, 10.0}) {
    const ImageQuality q = assessor.assess(scene::add_noise(ramp, sigma, 2));
    EXPECT_TRUE(q.noise_known);
    // The homogeneous mask keeps the 90 % lowest gradients, which biases sigma_n low by ~15 %;
    // 8-bit rounding adds 0.29 grey in quadrature.
    EXPECT_NEAR(q.noise_sigma, std::hypot(sigma, 0.29), 0.25 * sigma) << sigma;
  }
}

TEST(ImageQuality, ConfidenceFallsWithNoise) {
  QualityAssessor assessor({});
  const cv::Mat scene = textured(0.5);
  double previous_sigma = -1, previous_confidence = 2;
  for (const double sigma : {0.5, 2.0, 5.0, 10.0}) {
    const ImageQuality q = assessor.assess(scene::add_noise(scene, sigma, 3));
    EXPECT_GT(q.noise_sigma, previous_sigma) << sigma;
    EXPECT_LT(q.confidence, previous_confidence) << sigma;
    EXPECT_GT(q.omega, 0);
    previous_sigma = q.noise_sigma;
    previous_confidence = q.confidence;
  }
}

TEST(ImageQuality, GradientMetricAndConfidenceFallWithDarkness) {
  // The same scene under less light: contrast shrinks, the sensor noise stays (2 grey levels).
  QualityAssessor assessor({});
  double previous_g = 2, previous_confidence = 2, confidence_at_035 = 0;
  for (const double brightness : {1.0, 0.7, 0.5, 0.35, 0.25}) {
    const ImageQuality q = assessor.assess(scene::add_noise(textured(0.6, brightness), 2.0, 4));
    EXPECT_LT(q.gradient_metric, previous_g) << brightness;
    EXPECT_LT(q.confidence, previous_confidence) << brightness;
    previous_g = q.gradient_metric;
    previous_confidence = q.confidence;
    if (brightness == 0.35) confidence_at_035 = q.confidence;
  }
  // At a tenth of the light the texture has sunk below the noise: no edges left, and the
  // confidence rests on the noise alone, below that of images that still had texture.
  const ImageQuality q = assessor.assess(scene::add_noise(textured(0.6, 0.1), 2.0, 4));
  EXPECT_LT(q.gradient_metric, 0.01);
  EXPECT_LT(q.confidence, confidence_at_035);
}

TEST(ImageQuality, NoiseAloneIsNotTexture) {
  QualityAssessor assessor({});
  for (const double sigma : {2.0, 5.0, 10.0}) {
    const cv::Mat noise = scene::add_noise(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)), sigma, 9);
    EXPECT_LT(assessor.assess(noise).edge_fraction, 1e-3) << sigma;
  }
}

TEST(ImageQuality, BlackFrameHasUnknownNoiseAndLowestConfidence) {
  QualityConfig config;
  QualityAssessor assessor(config);
  const ImageQuality q = assessor.assess(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)));
  EXPECT_FALSE(q.noise_known);  // every pixel is saturated low
  EXPECT_EQ(q.noise_sigma, config.unknown_noise_sigma);
  EXPECT_EQ(q.edge_pixels, 0u);
  EXPECT_EQ(q.gradient_metric, 0.0);
  // omega = 0.5 (20 + 4 (1 - 0)) = 12: confidence 1/12.
  EXPECT_NEAR(q.omega, 12.0, 1e-12);
  EXPECT_NEAR(q.confidence, 1.0 / 12.0, 1e-12);
}

TEST(ImageQuality, WeighClampsOmega) {
  QualityConfig config;
  ImageQuality q;
  q.noise_sigma = 0.0;
  q.gradient_metric = 1.0;
  weigh(config, q);
  EXPECT_EQ(q.omega, config.omega_min);
  EXPECT_EQ(q.confidence, 1.0);
  q.noise_sigma = 1e6;
  weigh(config, q);
  EXPECT_EQ(q.omega, config.omega_max);
  EXPECT_NEAR(q.confidence, config.omega_min / config.omega_max, 1e-15);
}

TEST(ImageQuality, EdgeCountUsesTheSlopeThreshold) {
  // A noiseless ramp of 7 grey/px has G = 7 everywhere inside: all edges at threshold 6, none
  // at 8.
  cv::Mat ramp(32, 32, CV_8UC1);
  for (int r = 0; r < 32; ++r)
    for (int c = 0; c < 32; ++c) ramp.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(7 * c);
  QualityConfig config;
  config.edge_gradient = 6;
  config.row_step = 1;
  EXPECT_EQ(QualityAssessor(config).assess(ramp).edge_pixels, 30u * 30u);
  config.row_step = 2;  // interior rows 1, 3, ..., 29
  EXPECT_EQ(QualityAssessor(config).assess(ramp).pixels, 15u * 30u);
  EXPECT_EQ(QualityAssessor(config).assess(ramp).edge_pixels, 15u * 30u);
  config.edge_gradient = 8;
  EXPECT_EQ(QualityAssessor(config).assess(ramp).edge_pixels, 0u);
}

}  // namespace
}  // namespace posed::vision
