// The patch shape (core/vision/patch_shape): a corner fixes a point both ways, a straight edge
// only across itself, a flat patch says nothing and is left isotropic.

#include "core/vision/patch_shape.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace posed::vision {
namespace {

Eigen::Vector2d eigenvalues(const Eigen::Matrix2d& m) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(m).eigenvalues();
}

TEST(PatchShape, ACornerFixesBothDirections) {
  cv::Mat grey(60, 60, CV_8UC1, cv::Scalar(40));
  cv::rectangle(grey, cv::Rect(30, 30, 30, 30), cv::Scalar(200), cv::FILLED);
  const Eigen::Vector2d l = eigenvalues(patch_shape(grey, {30, 30}, 7));
  EXPECT_NEAR(l(1), 1.0, 1e-12);
  EXPECT_GT(l(0), 0.5);
}

TEST(PatchShape, AStraightEdgeFixesOnlyAcrossItself) {
  // An edge at 30 degrees from the x axis: the patch fixes the point along its normal.
  cv::Mat grey(80, 80, CV_8UC1, cv::Scalar(40));
  const double angle = 30.0 * M_PI / 180.0;
  const Eigen::Vector2d along(std::cos(angle), std::sin(angle)), across(-along.y(), along.x());
  for (int y = 0; y < grey.rows; ++y)
    for (int x = 0; x < grey.cols; ++x)
      if (across.dot(Eigen::Vector2d(x - 40, y - 40)) > 0) grey.at<std::uint8_t>(y, x) = 200;
  cv::GaussianBlur(grey, grey, cv::Size(5, 5), 1.0);
  const Eigen::Matrix2d shape = patch_shape(grey, {40, 40}, 7);
  EXPECT_LT(along.dot(shape * along), 0.05);
  EXPECT_GT(across.dot(shape * across), 0.95);
}

TEST(PatchShape, AFlatPatchIsIsotropic) {
  const cv::Mat grey(40, 40, CV_8UC1, cv::Scalar(90));
  EXPECT_TRUE(patch_shape(grey, {20, 20}, 7).isIdentity());
  // At the border the window is clipped to the image.
  EXPECT_TRUE(patch_shape(grey, {0, 39}, 7).isIdentity());
}

}  // namespace
}  // namespace posed::vision
