// select_corners against cv::goodFeaturesToTrack: the same corners in the same order, on
// textured and plain images, with and without a mask, with and without a minimum distance.

#include "core/vision/corner_selection.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace posed::vision {
namespace {

/// Rectangles, discs and noise over a ramp: corners of every strength, plain stretches and
/// equal scores (the rectangles' corners), on a `size` image.
cv::Mat texture(cv::Size size, int seed) {
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  cv::Mat image(size, CV_8UC1);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x)
      image.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(x / 4 + 40);
  }
  for (int i = 0; i < 40; ++i) {
    const cv::Point a(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Point b = a + cv::Point(rng.uniform(4, 40), rng.uniform(4, 40));
    cv::rectangle(image, a, b, cv::Scalar(rng.uniform(0, 256)), cv::FILLED);
    cv::circle(image, cv::Point(rng.uniform(0, size.width), rng.uniform(0, size.height)),
               rng.uniform(2, 15), cv::Scalar(rng.uniform(0, 256)), cv::FILLED);
  }
  cv::Mat noise(size, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 6);
  image += noise;
  return image;
}

TEST(CornerSelection, ChoosesTheCornersGoodFeaturesToTrackChooses) {
  int compared = 0, nonempty = 0;
  for (int seed = 1; seed <= 6; ++seed) {
    const cv::Size size = seed % 2 == 0 ? cv::Size(320, 240) : cv::Size(213, 161);
    const cv::Mat image = texture(size, seed);
    cv::Mat mask(size, CV_8UC1, cv::Scalar(255));
    cv::circle(mask, cv::Point(size.width / 3, size.height / 2), size.height / 4, cv::Scalar(0),
               cv::FILLED);
    for (const bool masked : {false, true}) {
      for (const double min_distance : {0.0, 0.5, 1.0, 7.5, 15.0}) {
        for (const int max_corners : {0, 25, 300}) {
          for (const int block : {3, 5}) {
            const cv::Mat& m = masked ? mask : cv::Mat();
            std::vector<cv::Point2f> expected;
            cv::goodFeaturesToTrack(image, expected, max_corners, 0.01, min_distance, m, block);
            cv::Mat score;
            cv::cornerMinEigenVal(image, score, block, 3);
            std::vector<cv::Point2f> corners = {cv::Point2f(1, 1)};  // replaced, not appended to
            select_corners(score, m, max_corners, 0.01, min_distance, corners);
            ASSERT_EQ(corners.size(), expected.size())
                << "seed " << seed << " masked " << masked << " min_distance " << min_distance
                << " max_corners " << max_corners << " block " << block;
            for (std::size_t i = 0; i < corners.size(); ++i) {
              ASSERT_EQ(corners[i], expected[i]) << "corner " << i << ", seed " << seed;
            }
            ++compared;
            if (!corners.empty()) ++nonempty;
          }
        }
      }
    }
  }
  EXPECT_EQ(compared, 6 * 2 * 5 * 3 * 2);
  EXPECT_EQ(nonempty, compared);
}

TEST(CornerSelection, AMaskThatExcludesEverythingGivesNoCorners) {
  const cv::Mat image = texture(cv::Size(160, 120), 9);
  cv::Mat score;
  cv::cornerMinEigenVal(image, score, 3, 3);
  std::vector<cv::Point2f> corners;
  select_corners(score, cv::Mat::zeros(image.size(), CV_8UC1), 100, 0.01, 10, corners);
  EXPECT_TRUE(corners.empty());
}

TEST(CornerSelection, TheCountingSelectionFindsTheValueNthElementFinds) {
  cv::RNG rng(3);
  int checked = 0;
  for (int trial = 0; trial < 40; ++trial) {
    // Scores as cornerMinEigenVal gives them (mostly small, some exactly 0 or -0, a rounding
    // error below 0, many repeated), and a view into a larger image (rows not contiguous).
    cv::Mat image(61, 97, CV_32FC1);
    for (int y = 0; y < image.rows; ++y) {
      for (int x = 0; x < image.cols; ++x) {
        const int kind = rng.uniform(0, 10);
        float v = static_cast<float>(rng.uniform(0.0, 1.0) * std::pow(10.0, rng.uniform(-9, 3)));
        if (kind == 0) v = 0.f;
        if (kind == 1) v = -0.f;
        if (kind == 2) v = -v * 1e-6f;
        if (kind == 3) v = 0.25f;
        image.at<float>(y, x) = v;
      }
    }
    const cv::Mat values = trial % 2 == 0 ? image : image(cv::Rect(3, 5, 50, 40));
    std::vector<float> copy;
    for (int y = 0; y < values.rows; ++y) {
      for (int x = 0; x < values.cols; ++x) copy.push_back(values.at<float>(y, x));
    }
    for (const std::size_t n :
         {std::size_t{0}, copy.size() / 2, copy.size() / 3,
          static_cast<std::size_t>(rng.uniform(0, static_cast<int>(copy.size()))),
          copy.size() - 1}) {
      std::vector<float> sorted = copy;
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n),
                       sorted.end());
      const float found = nth_smallest(values, n);
      EXPECT_EQ(found, sorted[n]) << "trial " << trial << ", n " << n;  // -0 == +0
      ++checked;
    }
  }
  EXPECT_EQ(checked, 200);
}

}  // namespace
}  // namespace posed::vision
