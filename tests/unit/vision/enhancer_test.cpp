// Seed 001's enhancement: the adaptive gamma lifts dark images and tones down bright ones within
// its clamp; the enhancement is exactly the HSV recipe (hue and saturation kept, only V changed),
// its grey shortcut equals the grey of the enhanced colour image, and a dark scene gains
// brightness and contrast.

#include "core/vision/enhancer.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::vision {
namespace {

/// A colour scene: the wall texture tinted differently per channel, scaled by `brightness`.
cv::Mat colour_scene(double brightness) {
  const cv::Mat a = scene::texture_image(640, 480, 0.01, 230 * brightness, 5, 11);
  const cv::Mat b = scene::texture_image(640, 480, 0.013, 200 * brightness, 10, 12);
  const cv::Mat c = scene::texture_image(640, 480, 0.008, 160 * brightness, 3, 13);
  cv::Mat bgr;
  cv::merge(std::vector<cv::Mat>{a, b, c}, bgr);
  return bgr;
}

TEST(AdaptiveGamma, DarkImagesGetGammaBelowOneBrightOnesAbove) {
  const EnhanceConfig config;
  EXPECT_LT(adaptive_gamma(0.1, config), 1.0);
  EXPECT_NEAR(adaptive_gamma(0.5, config), 1.0, 1e-12);  // already at the target mean
  EXPECT_GT(adaptive_gamma(0.8, config), 1.0);
  // The mean maps to the target: 0.2^gamma = 0.5.
  EXPECT_NEAR(std::pow(0.2, adaptive_gamma(0.2, config)), 0.5, 1e-12);
  // Clamped: a black frame must not turn its noise into full-range texture.
  EXPECT_DOUBLE_EQ(adaptive_gamma(0.0, config), config.gamma_min);
  EXPECT_DOUBLE_EQ(adaptive_gamma(1.0, config), config.gamma_max);
}

TEST(Enhancer, KeepsHueAndSaturationExactly) {
  Enhancer enhancer({});
  const cv::Mat bgr = colour_scene(0.3);
  cv::Mat out;
  enhancer.enhance_colour(bgr, out);
  // Every channel is scaled by the same V'/V: channel ratios (hue, saturation) are kept, up to
  // 8-bit rounding of each channel.
  double worst = 0;
  for (int r = 0; r < bgr.rows; r += 5) {
    for (int c = 0; c < bgr.cols; c += 5) {
      const cv::Vec3b in = bgr.at<cv::Vec3b>(r, c), o = out.at<cv::Vec3b>(r, c);
      const int vin = std::max({in[0], in[1], in[2]}), vout = std::max({o[0], o[1], o[2]});
      if (vin < 20 || vout < 20) continue;
      for (int k = 0; k < 3; ++k) {
        worst = std::max(worst, std::abs(in[k] / double(vin) - o[k] / double(vout)));
      }
    }
  }
  EXPECT_LT(worst, 0.03);
}

TEST(Enhancer, AgreesWithOpenCvsHsvRoundTrip) {
  // The reference: cvtColor to HSV (full-range hue), V replaced by the same enhanced V, back.
  const cv::Mat bgr = colour_scene(0.25);
  Enhancer enhancer({});
  cv::Mat ours;
  enhancer.enhance_colour(bgr, ours);
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV_FULL);
  std::vector<cv::Mat> channels;
  cv::split(hsv, channels);
  Enhancer reference_enhancer({});
  cv::Mat value;
  reference_enhancer.enhance_value(channels[2], value);
  channels[2] = value;
  cv::merge(channels, hsv);
  cv::Mat reference;
  cv::cvtColor(hsv, reference, cv::COLOR_HSV2BGR_FULL);
  cv::Mat diff;
  cv::absdiff(ours, reference, diff);
  // OpenCV quantises hue to 256 levels and saturation to 8 bits: a few grey levels apart.
  EXPECT_LT(cv::mean(diff)[0], 2.0);
}

TEST(Enhancer, GreyShortcutEqualsGreyOfTheEnhancedColourImage) {
  const cv::Mat bgr = colour_scene(0.3);
  Enhancer a({}), b({});
  cv::Mat grey, colour, grey_of_colour;
  a.enhance_to_grey(bgr, false, grey);
  b.enhance_colour(bgr, colour);
  cv::cvtColor(colour, grey_of_colour, cv::COLOR_BGR2GRAY);
  EXPECT_LE(cv::norm(grey, grey_of_colour, cv::NORM_INF), 2.0);  // two roundings apart
}

TEST(Enhancer, RgbOrderGivesTheSameGrey) {
  const cv::Mat bgr = colour_scene(0.3);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  Enhancer a({}), b({});
  cv::Mat g1, g2;
  a.enhance_to_grey(bgr, false, g1);
  b.enhance_to_grey(rgb, true, g2);
  EXPECT_EQ(cv::norm(g1, g2, cv::NORM_INF), 0.0);
}

TEST(Enhancer, DarkSceneGainsBrightnessAndContrast) {
  const cv::Mat dark = scene::add_noise(scene::texture_image(640, 480, 0.01, 40, 2, 21), 1.0, 5);
  Enhancer enhancer({});
  cv::Mat out;
  const EnhanceStats stats = enhancer.enhance_to_grey(dark, false, out);
  cv::Scalar mean_in, std_in, mean_out, std_out;
  cv::meanStdDev(dark, mean_in, std_in);
  cv::meanStdDev(out, mean_out, std_out);
  EXPECT_LT(stats.gamma, 1.0);
  EXPECT_GT(mean_out[0], 2.0 * mean_in[0]);
  EXPECT_GT(std_out[0], 2.0 * std_in[0]);
}

TEST(Enhancer, DisabledOnlyConvertsToGrey) {
  EnhanceConfig config;
  config.enabled = false;
  Enhancer enhancer(config);
  const cv::Mat bgr = colour_scene(0.5);
  cv::Mat grey, expected;
  enhancer.enhance_to_grey(bgr, false, grey);
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(grey, expected, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace posed::vision
