// The lens model both cameras use: projection and its Gauss-Newton inverse agree to far below a
// pixel over the whole image, including the thermal lens's strong barrel distortion.

#include "core/vision/pinhole_camera.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>

#include "core/vision/undistorter.hpp"
#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::vision {
namespace {

void expect_round_trip(const PinholeCamera& camera) {
  double worst_px = 0;
  for (int r = 0; r < camera.height; r += 7) {
    for (int c = 0; c < camera.width; c += 7) {
      const Eigen::Vector2d pixel(c, r);
      Eigen::Vector2d xy;
      ASSERT_TRUE(camera.normalised_from_pixel(pixel, xy)) << c << "," << r;
      Eigen::Vector2d back;
      ASSERT_TRUE(camera.project(Eigen::Vector3d(xy.x(), xy.y(), 1.0) * 7.5, back));
      worst_px = std::max(worst_px, (back - pixel).norm());
    }
  }
  EXPECT_LT(worst_px, 1e-8);
}

TEST(PinholeCamera, UndistortionInvertsProjectionForTheM2dgrVisibleCamera) {
  expect_round_trip(scene::m2dgr_visible());
}

TEST(PinholeCamera, UndistortionInvertsProjectionForTheM2dgrThermalCamera) {
  expect_round_trip(scene::m2dgr_thermal());
}

TEST(PinholeCamera, TangentialTermsAreInverted) {
  PinholeCamera c = scene::m2dgr_visible();
  c.p1 = 0.002;
  c.p2 = -0.0015;
  expect_round_trip(c);
}

TEST(PinholeCamera, BarrelDistortionPullsTheCornersIn) {
  // k1 < 0: a ray at the image corner's undistorted position lands nearer the centre.
  const PinholeCamera thermal = scene::m2dgr_thermal();
  Eigen::Vector2d corner;
  ASSERT_TRUE(thermal.normalised_from_pixel(Eigen::Vector2d(0, 0), corner));
  const Eigen::Vector2d pinhole((0 - thermal.cx) / thermal.fx, (0 - thermal.cy) / thermal.fy);
  EXPECT_GT(corner.norm(), pinhole.norm() * 1.1);
}

TEST(PinholeCamera, PointsBehindTheCameraDoNotProject) {
  Eigen::Vector2d pixel;
  EXPECT_FALSE(scene::m2dgr_visible().project(Eigen::Vector3d(0.1, 0.2, -1.0), pixel));
}

TEST(PinholeCamera, FieldOfViewOfTheM2dgrCameras) {
  // 2 atan(W / 2 f): 54.752 x 42.545 deg visible, 72.574 x 60.850 deg thermal.
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  EXPECT_NEAR(scene::m2dgr_visible().horizontal_fov_rad() * kDeg, 54.752, 0.001);
  EXPECT_NEAR(scene::m2dgr_visible().vertical_fov_rad() * kDeg, 42.545, 0.001);
  EXPECT_NEAR(scene::m2dgr_thermal().horizontal_fov_rad() * kDeg, 72.574, 0.001);
  EXPECT_NEAR(scene::m2dgr_thermal().vertical_fov_rad() * kDeg, 60.850, 0.001);
}

TEST(Undistorter, TableAndOneStepMatchTheIterativeInverse) {
  for (const PinholeCamera& camera : {scene::m2dgr_visible(), scene::m2dgr_thermal()}) {
    const Undistorter undistorter(camera);
    cv::RNG rng(3);
    double worst = 0;
    for (int i = 0; i < 2000; ++i) {
      const Eigen::Vector2d pixel(rng.uniform(0.0, camera.width - 1.0),
                                  rng.uniform(0.0, camera.height - 1.0));
      Eigen::Vector2d exact;
      ASSERT_TRUE(camera.normalised_from_pixel(pixel, exact));
      worst = std::max(worst, (undistorter.normalised(pixel) - exact).norm());
    }
    EXPECT_LT(worst * camera.fx, 1e-6);  // [px]
    EXPECT_TRUE(std::isnan(undistorter.normalised({-1.0, 3.0}).x()));
    EXPECT_TRUE(std::isnan(undistorter.normalised({3.0, camera.height + 0.5}).y()));
  }
}

}  // namespace
}  // namespace posed::vision
