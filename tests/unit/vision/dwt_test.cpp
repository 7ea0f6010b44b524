// The 2-D DWT: lossless round trips (to float precision) for every wavelet on random, textured
// and real thermal images, the Mallat layout, and the transform's defining properties (a constant
// image has no detail; a vertical edge shows up in the HL band only).

#include "core/vision/dwt.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <opencv2/core.hpp>

#include "core/vision/thermal_normalizer.hpp"
#include "tests/common/realdata.hpp"
#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::vision {
namespace {

/// Largest |inverse(forward(image)) - image|; for 8-bit images also checks that rounding the
/// reconstruction gives the image back bit for bit.
double max_round_trip_error(Wavelet wavelet, int levels, const cv::Mat& image) {
  Dwt2d dwt(wavelet, levels);
  cv::Mat coeffs, back, reference;
  dwt.forward(image, coeffs);
  dwt.inverse(coeffs, back);
  image.convertTo(reference, CV_32F);
  if (image.type() == CV_8UC1) {
    cv::Mat rounded;
    back.convertTo(rounded, CV_8U);
    EXPECT_EQ(cv::norm(rounded, image, cv::NORM_INF), 0.0) << to_string(wavelet);
  }
  return cv::norm(back, reference, cv::NORM_INF);
}

class DwtRoundTrip : public ::testing::TestWithParam<Wavelet> {};

TEST_P(DwtRoundTrip, RandomImageIsReconstructedToFloatPrecision) {
  cv::Mat image(480, 640, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  for (const int levels : {1, 2, 3}) {
    EXPECT_LT(max_round_trip_error(GetParam(), levels, image), 1e-3) << levels << " levels";
  }
}

TEST_P(DwtRoundTrip, FloatImageWithLargeValuesIsReconstructed) {
  cv::Mat image(64, 96, CV_32FC1);
  cv::RNG rng(8);
  rng.fill(image, cv::RNG::UNIFORM, -1000.0, 1000.0);
  // Relative float precision: 1000 x a few tens of ulp.
  EXPECT_LT(max_round_trip_error(GetParam(), 2, image), 5e-3);
}

TEST_P(DwtRoundTrip, RealThermalFrameIsReconstructed) {
  POSED_REQUIRE_REALDATA(path, "thermal_16bit/frame_000000_640x512_u16le.raw");
  const std::vector<std::uint8_t> bytes = posed::test::read_bytes(path);
  ASSERT_EQ(bytes.size(), 640u * 512u * 2u);
  cv::Mat counts(512, 640, CV_16UC1);
  std::memcpy(counts.data, bytes.data(), bytes.size());  // little-endian, as the host
  cv::Mat grey;
  ThermalNormalizer normalizer({});
  normalizer.normalize(counts, {}, grey);
  EXPECT_LT(max_round_trip_error(GetParam(), 2, grey), 1e-3);
}

std::string wavelet_name(const ::testing::TestParamInfo<Wavelet>& param) {
  return std::string(to_string(param.param));
}

INSTANTIATE_TEST_SUITE_P(AllWavelets, DwtRoundTrip,
                         ::testing::Values(Wavelet::kHaar, Wavelet::kLeGall53, Wavelet::kCdf97),
                         wavelet_name);

TEST(Dwt, BandRectanglesFollowTheMallatLayout) {
  const cv::Size size(640, 480);
  EXPECT_EQ(Dwt2d::band_rect(size, 1, Band::kHL), cv::Rect(320, 0, 320, 240));
  EXPECT_EQ(Dwt2d::band_rect(size, 1, Band::kLH), cv::Rect(0, 240, 320, 240));
  EXPECT_EQ(Dwt2d::band_rect(size, 1, Band::kHH), cv::Rect(320, 240, 320, 240));
  EXPECT_EQ(Dwt2d::band_rect(size, 2, Band::kHH), cv::Rect(160, 120, 160, 120));
  EXPECT_EQ(Dwt2d::band_rect(size, 2, Band::kLL), cv::Rect(0, 0, 160, 120));
  EXPECT_EQ(Dwt2d(Wavelet::kHaar, 2).padded_size(cv::Size(641, 479)), cv::Size(644, 480));
}

TEST(Dwt, ConstantImageHasOnlyALowBand) {
  for (const Wavelet w : {Wavelet::kHaar, Wavelet::kLeGall53, Wavelet::kCdf97}) {
    cv::Mat image(32, 48, CV_8UC1, cv::Scalar(100));
    cv::Mat coeffs;
    Dwt2d dwt(w, 2);
    dwt.forward(image, coeffs);
    const cv::Rect low = Dwt2d::band_rect(image.size(), 2, Band::kLL);
    cv::Mat details = coeffs.clone();
    details(low).setTo(0);
    EXPECT_LT(cv::norm(details, cv::NORM_INF), 1e-3) << to_string(w);
    EXPECT_GT(cv::mean(coeffs(low))[0], 99.0) << to_string(w);
  }
}

TEST(Dwt, HaarLowBandIsTheScaledBlockMean) {
  // Orthonormal Haar: each level multiplies a block mean by 2 (sqrt 2 per direction).
  cv::Mat image(8, 8, CV_32FC1);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c) image.at<float>(r, c) = static_cast<float>(r * 8 + c);
  cv::Mat coeffs;
  Dwt2d(Wavelet::kHaar, 2).forward(image, coeffs);
  // Top-left 4x4 block of the image: mean of rows 0..3, cols 0..3 = 13.5; times 4.
  EXPECT_NEAR(coeffs.at<float>(0, 0), 4 * 13.5, 1e-4);
}

TEST(Dwt, VerticalEdgeAppearsInTheHorizontalDetailBandOnly) {
  cv::Mat image(64, 64, CV_8UC1, cv::Scalar(50));
  image(cv::Rect(33, 0, 31, 64)).setTo(200);  // edge between columns 32 and 33 (odd boundary)
  cv::Mat coeffs;
  Dwt2d(Wavelet::kLeGall53, 1).forward(image, coeffs);
  EXPECT_GT(cv::norm(coeffs(Dwt2d::band_rect(image.size(), 1, Band::kHL)), cv::NORM_INF), 50.0);
  EXPECT_LT(cv::norm(coeffs(Dwt2d::band_rect(image.size(), 1, Band::kLH)), cv::NORM_INF), 1e-3);
  EXPECT_LT(cv::norm(coeffs(Dwt2d::band_rect(image.size(), 1, Band::kHH)), cv::NORM_INF), 1e-3);
}

}  // namespace
}  // namespace posed::vision
