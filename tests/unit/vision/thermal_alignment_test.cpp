// Thermal preprocessing (seed 000 §2.1.1) and pairing compensation: the eq. (6) crop for the
// M2DGR intrinsics, registration of a known far point, whole rendered scenes registered through
// both lenses, the inter-stamp rotation, and the 16 -> 8-bit normalisation.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "core/vision/fov_compensation.hpp"
#include "core/vision/thermal_aligner.hpp"
#include "core/vision/thermal_normalizer.hpp"
#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::vision {
namespace {

using scene::m2dgr_T_cam_thermal;
using scene::m2dgr_thermal;
using scene::m2dgr_visible;

TEST(FovCompensation, CropSizeFollowsEquationSixForTheM2dgrIntrinsics) {
  // X' = 2 d_x tan(beta'/2) with beta' = 2 atan(640 / (2 * 617.971)): X' = 640 * 435.836 / 617.971
  // = 451.3725 px; Y' = 480 * 435.909 / 616.445 = 339.4244 px (hand-computed from the calibration).
  const FovCrop crop = fov_crop(m2dgr_thermal(), m2dgr_visible());
  EXPECT_NEAR(crop.width_px, 451.3725, 1e-3);
  EXPECT_NEAR(crop.height_px, 339.4244, 1e-3);
  EXPECT_NEAR(crop.left_px, 324.452753232850 - 451.3725 / 2, 1e-3);
  EXPECT_NEAR(crop.top_px, 255.554320082190 - 339.4244 / 2, 1e-3);
}

TEST(FovCompensation, CropOfTheFieldsOfViewInTheSeedsTable1) {
  // Seed 000's Table 1 gives the visible camera 69 x 42.5 deg (the D435's full sensor):
  // X' = 2 * 435.836 * tan(34.5 deg) = 599.08 px, Y' = 2 * 435.909 * tan(21.25 deg) = 339.03 px.
  constexpr double kDeg = std::numbers::pi / 180.0;
  const FovCrop crop = fov_crop(m2dgr_thermal(), 69.0 * kDeg, 42.5 * kDeg);
  EXPECT_NEAR(crop.width_px, 599.08, 0.01);
  EXPECT_NEAR(crop.height_px, 339.03, 0.01);
}

ThermalAligner make_aligner(AlignMode mode, double plane_depth_m = 10.0,
                            bool rotation_compensation = true) {
  ThermalAlignConfig config;
  config.mode = mode;
  config.plane_depth_m = plane_depth_m;
  config.rotation_compensation = rotation_compensation;
  return ThermalAligner(m2dgr_visible(), m2dgr_thermal(), m2dgr_T_cam_thermal(), config);
}

TEST(ThermalAligner, KnownFarPointMapsToItsThermalPixel) {
  ThermalAligner aligner = make_aligner(AlignMode::kInfiniteHomography);
  const Eigen::Isometry3d T_thermal_cam = m2dgr_T_cam_thermal().inverse();
  for (const Eigen::Vector3d& direction :
       {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.4, -0.3, 1), Eigen::Vector3d(-0.45, 0.35, 1),
        Eigen::Vector3d(0.3, 0.38, 1)}) {
    const Eigen::Vector3d p_cam = 1e4 * direction;  // 10 km: the 0.17 m baseline is 0.007 px
    Eigen::Vector2d visible_px, expected_px, mapped_px;
    ASSERT_TRUE(m2dgr_visible().project(p_cam, visible_px));
    ASSERT_TRUE(m2dgr_thermal().project(T_thermal_cam * p_cam, expected_px));
    ASSERT_TRUE(aligner.thermal_pixel(visible_px, Eigen::Matrix3d::Identity(), mapped_px));
    EXPECT_LT((mapped_px - expected_px).norm(), 0.02) << direction.transpose();
  }
}

TEST(ThermalAligner, KnownFarPointLandsOnItsVisiblePixelInTheImage) {
  // A warm spot at the thermal pixel of a far point must come out of align() centred on the
  // point's visible pixel.
  ThermalAligner aligner = make_aligner(AlignMode::kInfiniteHomography);
  const Eigen::Vector3d p_cam(-1200, 900, 5000);
  Eigen::Vector2d visible_px, thermal_px;
  ASSERT_TRUE(m2dgr_visible().project(p_cam, visible_px));
  ASSERT_TRUE(m2dgr_thermal().project(m2dgr_T_cam_thermal().inverse() * p_cam, thermal_px));
  cv::Mat thermal(512, 640, CV_8UC1);
  for (int r = 0; r < 512; ++r)
    for (int c = 0; c < 640; ++c) {
      const double d2 = std::pow(c - thermal_px.x(), 2) + std::pow(r - thermal_px.y(), 2);
      thermal.at<std::uint8_t>(r, c) = cv::saturate_cast<std::uint8_t>(250 * std::exp(-d2 / 18));
    }
  cv::Mat aligned;
  AlignStats stats;
  ASSERT_TRUE(aligner.align(thermal, Eigen::Matrix3d::Identity(), aligned, stats));
  ASSERT_EQ(aligned.size(), cv::Size(640, 480));
  const cv::Moments m = cv::moments(aligned);
  ASSERT_GT(m.m00, 0);
  EXPECT_NEAR(m.m10 / m.m00, visible_px.x(), 0.25);
  EXPECT_NEAR(m.m01 / m.m00, visible_px.y(), 0.25);
  EXPECT_EQ(stats.invalid_pixels, 0);  // the visible FOV lies inside the thermal one
}

TEST(ThermalAligner, PlaneModeIncludesTheBaseline) {
  ThermalAligner aligner = make_aligner(AlignMode::kPlane, 5.0);
  const Eigen::Vector3d p_cam(1.1, -0.7, 5.0);  // on the plane z = 5 m
  Eigen::Vector2d visible_px, expected_px, mapped_px;
  ASSERT_TRUE(m2dgr_visible().project(p_cam, visible_px));
  ASSERT_TRUE(m2dgr_thermal().project(m2dgr_T_cam_thermal().inverse() * p_cam, expected_px));
  ASSERT_TRUE(aligner.thermal_pixel(visible_px, Eigen::Matrix3d::Identity(), mapped_px));
  EXPECT_LT((mapped_px - expected_px).norm(), 1e-6);
  // On the optical axis the homography at infinity misses by f b / z = 435.84 * 0.17 / 5 =
  // 14.82 px (the lens's distortion changes that by 0.05 % there).
  const Eigen::Vector3d on_axis(0, 0, 5.0);
  ASSERT_TRUE(m2dgr_visible().project(on_axis, visible_px));
  ASSERT_TRUE(m2dgr_thermal().project(m2dgr_T_cam_thermal().inverse() * on_axis, expected_px));
  ThermalAligner infinite = make_aligner(AlignMode::kInfiniteHomography);
  ASSERT_TRUE(infinite.thermal_pixel(visible_px, Eigen::Matrix3d::Identity(), mapped_px));
  EXPECT_NEAR((mapped_px - expected_px).norm(), 435.836 * 0.17 / 5.0, 0.02);
}

/// Mean absolute difference over the central region (away from the borders' interpolation).
double mean_difference(const cv::Mat& a, const cv::Mat& b) {
  const cv::Rect inner(20, 20, a.cols - 40, a.rows - 40);
  cv::Mat diff;
  cv::absdiff(a(inner), b(inner), diff);
  return cv::mean(diff)[0];
}

TEST(ThermalAligner, RegistersAWholeRenderedSceneThroughBothLenses) {
  // One textured wall 6 m ahead, rendered by each camera through its own distortion.
  const double depth = 6.0;
  const auto visible_rays = scene::pixel_rays(m2dgr_visible());
  const auto thermal_rays = scene::pixel_rays(m2dgr_thermal());
  const cv::Mat visible = scene::render_wall(m2dgr_visible(), visible_rays,
                                             Eigen::Isometry3d::Identity(), depth, 200, 20, 1);
  const cv::Mat thermal =
      scene::render_wall(m2dgr_thermal(), thermal_rays, m2dgr_T_cam_thermal(), depth, 200, 20, 1);
  cv::Mat aligned;
  AlignStats stats;
  ThermalAligner plane = make_aligner(AlignMode::kPlane, depth);
  ASSERT_TRUE(plane.align(thermal, Eigen::Matrix3d::Identity(), aligned, stats));
  const double registered = mean_difference(aligned, visible);
  EXPECT_LT(registered, 4.0);  // thermal resolution is 0.7x the visible one: some blur
  // At infinity the 0.17 m baseline shifts the wall by ~17 px: clearly misregistered.
  ThermalAligner infinite = make_aligner(AlignMode::kInfiniteHomography);
  ASSERT_TRUE(infinite.align(thermal, Eigen::Matrix3d::Identity(), aligned, stats));
  EXPECT_GT(mean_difference(aligned, visible), 3 * registered);
}

TEST(ThermalAligner, CompensatesTheCameraRotationBetweenTheStamps) {
  // The camera turned 1.2 deg (yaw and pitch) between the thermal and the visible exposure.
  const double depth = 6.0;
  const Eigen::Matrix3d R_camtv_camtt = (Eigen::AngleAxisd(0.018, Eigen::Vector3d::UnitY()) *
                                         Eigen::AngleAxisd(-0.011, Eigen::Vector3d::UnitX()))
                                            .toRotationMatrix();
  const auto visible_rays = scene::pixel_rays(m2dgr_visible());
  const auto thermal_rays = scene::pixel_rays(m2dgr_thermal());
  const cv::Mat visible = scene::render_wall(m2dgr_visible(), visible_rays,
                                             Eigen::Isometry3d::Identity(), depth, 200, 20, 2);
  Eigen::Isometry3d T_world_camtt = Eigen::Isometry3d::Identity();
  T_world_camtt.linear() = R_camtv_camtt;  // world = camera at the visible stamp
  const cv::Mat thermal = scene::render_wall(
      m2dgr_thermal(), thermal_rays, T_world_camtt * m2dgr_T_cam_thermal(), depth, 200, 20, 2);
  cv::Mat aligned;
  AlignStats stats;
  ThermalAligner compensated = make_aligner(AlignMode::kPlane, depth, true);
  ASSERT_TRUE(compensated.align(thermal, R_camtv_camtt, aligned, stats));
  EXPECT_TRUE(stats.rotation_compensated);
  EXPECT_NEAR(stats.rotation_rad, std::hypot(0.018, 0.011), 1e-4);
  const double with = mean_difference(aligned, visible);
  EXPECT_LT(with, 4.0);
  ThermalAligner uncompensated = make_aligner(AlignMode::kPlane, depth, false);
  ASSERT_TRUE(uncompensated.align(thermal, R_camtv_camtt, aligned, stats));
  EXPECT_FALSE(stats.rotation_compensated);
  EXPECT_GT(mean_difference(aligned, visible), 3 * with);
}

TEST(ThermalAligner, TinyRotationsUseThePrecomputedMap) {
  ThermalAligner aligner = make_aligner(AlignMode::kInfiniteHomography);
  cv::Mat thermal(512, 640, CV_8UC1, cv::Scalar(90)), aligned;
  AlignStats stats;
  // 1e-4 rad moves the image by 0.06 px: below the 0.1 px threshold.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1e-4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  ASSERT_TRUE(aligner.align(thermal, R, aligned, stats));
  EXPECT_FALSE(stats.rotation_compensated);
}

TEST(ThermalAligner, FovCropModeSamplesTheEquationSixRegion) {
  ThermalAligner aligner = make_aligner(AlignMode::kFovCrop);
  const FovCrop& crop = aligner.fov_crop();
  // The visible image's centre (319.5, 239.5) samples the crop's centre, i.e. the thermal
  // principal point (undistorted = distorted there).
  Eigen::Vector2d thermal_px;
  ASSERT_TRUE(aligner.thermal_pixel({319.5, 239.5}, Eigen::Matrix3d::Identity(), thermal_px));
  EXPECT_NEAR(thermal_px.x(), m2dgr_thermal().cx, 1e-6);
  EXPECT_NEAR(thermal_px.y(), m2dgr_thermal().cy, 1e-6);
  // The left edge of the visible image (pixel -0.5) samples the crop's left edge (undistorted).
  ASSERT_TRUE(aligner.thermal_pixel({-0.5, 239.5}, Eigen::Matrix3d::Identity(), thermal_px));
  const PinholeCamera t = m2dgr_thermal();
  const Eigen::Vector2d edge = t.pixel_from_normalised({(crop.left_px - t.cx) / t.fx, 0.0});
  EXPECT_NEAR(thermal_px.x(), edge.x(), 1e-6);
}

/// Lidar-like points on the rectangle x in [x0, x1], y in [y0, y1] of the plane z = depth_m
/// (visible camera frame): rings every `ring_rad` of elevation, 0.2 deg apart along a ring.
std::vector<Eigen::Vector3f> plane_points(double depth_m, double x0, double x1, double y0,
                                          double y1, double ring_rad) {
  std::vector<Eigen::Vector3f> points;
  for (double elevation = -0.6; elevation <= 0.6; elevation += ring_rad) {
    for (double azimuth = -0.8; azimuth <= 0.8; azimuth += 0.0035) {
      const Eigen::Vector3d d(std::sin(azimuth) * std::cos(elevation), std::sin(elevation),
                              std::cos(azimuth) * std::cos(elevation));
      const Eigen::Vector3d p = d * (depth_m / d.z());
      if (p.x() >= x0 && p.x() <= x1 && p.y() >= y0 && p.y() <= y1) {
        points.push_back(p.cast<float>());
      }
    }
  }
  return points;
}

/// A warm spot (Gaussian, sigma 2 px) at a thermal pixel, on a black 640x512 frame.
cv::Mat warm_spot(const Eigen::Vector2d& thermal_px) {
  cv::Mat thermal(512, 640, CV_8UC1);
  for (int r = 0; r < 512; ++r)
    for (int c = 0; c < 640; ++c) {
      const double d2 = std::pow(c - thermal_px.x(), 2) + std::pow(r - thermal_px.y(), 2);
      thermal.at<std::uint8_t>(r, c) = cv::saturate_cast<std::uint8_t>(250 * std::exp(-d2 / 8));
    }
  return thermal;
}

TEST(ThermalAligner, LidarDepthPutsANearThermalSpotOnItsVisiblePixel) {
  // A board 3 m ahead in front of a wall 40 m away, both sampled by lidar rings 2 deg apart
  // (further apart than the depth grid's rows: some cells are filled from their neighbours). A
  // warm spot on the board must land on the board point's visible pixel; at infinity it is
  // displaced by the parallax f_v b / z = 617.97 * 0.17 / 3 = 35.0 px.
  const double z = 3.0;
  const Eigen::Vector3d p_cam(-0.4, 0.1, z);
  std::vector<Eigen::Vector3f> points = plane_points(z, -1.2, 0.4, -0.6, 0.6, 0.035);
  const std::vector<Eigen::Vector3f> wall = plane_points(40.0, -100, 100, -100, 100, 0.035);
  const std::size_t board_points = points.size();
  for (const Eigen::Vector3f& p : wall) {
    // The wall behind the board is hidden from the lidar (which sits at the visible camera).
    if (!(p.x() / p.z() * z >= -1.2 && p.x() / p.z() * z <= 0.4 && p.y() / p.z() * z >= -0.6 &&
          p.y() / p.z() * z <= 0.6)) {
      points.push_back(p);
    }
  }
  ASSERT_GT(board_points, 500u);
  Eigen::Vector2d visible_px, thermal_px;
  ASSERT_TRUE(m2dgr_visible().project(p_cam, visible_px));
  ASSERT_TRUE(m2dgr_thermal().project(m2dgr_T_cam_thermal().inverse() * p_cam, thermal_px));
  const cv::Mat thermal = warm_spot(thermal_px);
  const auto centroid = [](const cv::Mat& image) {
    const cv::Moments m = cv::moments(image);
    return Eigen::Vector2d(m.m10 / m.m00, m.m01 / m.m00);
  };

  ThermalAligner depth_aware = make_aligner(AlignMode::kLidarDepth);
  cv::Mat aligned;
  AlignStats stats;
  ASSERT_TRUE(depth_aware.align(thermal, Eigen::Matrix3d::Identity(), aligned, stats, points));
  EXPECT_GT(stats.depth_cells, 0);
  EXPECT_GT(stats.depth_filled_cells, 0);  // the rows between the rings
  EXPECT_LT((centroid(aligned) - visible_px).norm(), 1.0);
  Eigen::Vector2d mapped_px;  // the same through the per-pixel query
  ASSERT_TRUE(depth_aware.thermal_pixel(visible_px, Eigen::Matrix3d::Identity(), mapped_px));
  EXPECT_LT((mapped_px - thermal_px).norm(), 0.5);
  ASSERT_FALSE(depth_aware.inverse_depth().empty());
  EXPECT_NEAR(depth_aware.inverse_depth().at<float>(static_cast<int>(std::lround(visible_px.y())),
                                                    static_cast<int>(std::lround(visible_px.x()))),
              1.0 / z, 1e-3);

  ThermalAligner infinite = make_aligner(AlignMode::kInfiniteHomography);
  ASSERT_TRUE(infinite.align(thermal, Eigen::Matrix3d::Identity(), aligned, stats));
  const double parallax_px = (centroid(aligned) - visible_px).norm();
  EXPECT_NEAR(parallax_px, 617.971 * 0.17 / z, 1.5);
}

TEST(ThermalAligner, LidarDepthWithoutPointsIsTheHomographyAtInfinity) {
  const cv::Mat thermal = scene::render_wall(m2dgr_thermal(), scene::pixel_rays(m2dgr_thermal()),
                                             m2dgr_T_cam_thermal(), 6.0, 200, 20, 3);
  cv::Mat depth_aligned, infinite_aligned;
  AlignStats stats;
  ThermalAligner depth_aware = make_aligner(AlignMode::kLidarDepth);
  ASSERT_TRUE(depth_aware.align(thermal, Eigen::Matrix3d::Identity(), depth_aligned, stats));
  EXPECT_EQ(stats.depth_cells, 0);
  EXPECT_TRUE(depth_aware.inverse_depth().empty());
  ThermalAligner infinite = make_aligner(AlignMode::kInfiniteHomography);
  ASSERT_TRUE(infinite.align(thermal, Eigen::Matrix3d::Identity(), infinite_aligned, stats));
  EXPECT_EQ(cv::norm(depth_aligned, infinite_aligned, cv::NORM_INF), 0);
  // Points behind the camera or nearer than depth_min_m do not count either.
  const std::vector<Eigen::Vector3f> useless = {{0, 0, -5}, {0.1f, 0, 0.2f}};
  ASSERT_TRUE(
      depth_aware.align(thermal, Eigen::Matrix3d::Identity(), depth_aligned, stats, useless));
  EXPECT_EQ(stats.depth_cells, 0);
}

TEST(ThermalAligner, LidarDepthRegistersAWholeRenderedSceneLikeThePlane) {
  // The rendered wall 6 m ahead, its depth known only from lidar rings 1.3 deg apart: as good as
  // registering the known plane.
  const double depth = 6.0;
  const cv::Mat visible = scene::render_wall(m2dgr_visible(), scene::pixel_rays(m2dgr_visible()),
                                             Eigen::Isometry3d::Identity(), depth, 200, 20, 1);
  const cv::Mat thermal = scene::render_wall(m2dgr_thermal(), scene::pixel_rays(m2dgr_thermal()),
                                             m2dgr_T_cam_thermal(), depth, 200, 20, 1);
  const std::vector<Eigen::Vector3f> points = plane_points(depth, -100, 100, -100, 100, 0.0227);
  cv::Mat aligned;
  AlignStats stats;
  ThermalAligner plane = make_aligner(AlignMode::kPlane, depth);
  ASSERT_TRUE(plane.align(thermal, Eigen::Matrix3d::Identity(), aligned, stats));
  const double plane_difference = mean_difference(aligned, visible);
  ThermalAligner depth_aware = make_aligner(AlignMode::kLidarDepth);
  ASSERT_TRUE(depth_aware.align(thermal, Eigen::Matrix3d::Identity(), aligned, stats, points));
  EXPECT_LT(mean_difference(aligned, visible), plane_difference + 0.1);
}

TEST(ThermalAligner, RejectsFramesOfTheWrongSizeOrType) {
  ThermalAligner aligner = make_aligner(AlignMode::kInfiniteHomography);
  cv::Mat aligned;
  AlignStats stats;
  EXPECT_FALSE(
      aligner.align(cv::Mat(480, 640, CV_8UC1), Eigen::Matrix3d::Identity(), aligned, stats));
  EXPECT_FALSE(
      aligner.align(cv::Mat(512, 640, CV_32FC1), Eigen::Matrix3d::Identity(), aligned, stats));
  EXPECT_TRUE(aligned.empty());
}

TEST(ThermalAligner, SixteenBitFramesAreNormalisedAfterRegistration) {
  ThermalAligner aligner = make_aligner(AlignMode::kInfiniteHomography);
  cv::Mat counts(512, 640, CV_16UC1);
  for (int r = 0; r < 512; ++r)
    for (int c = 0; c < 640; ++c)
      counts.at<std::uint16_t>(r, c) = static_cast<std::uint16_t>(3000 + c / 4);
  cv::Mat aligned;
  AlignStats stats;
  ASSERT_TRUE(aligner.align(counts, Eigen::Matrix3d::Identity(), aligned, stats));
  EXPECT_TRUE(stats.normalized);
  ASSERT_EQ(aligned.type(), CV_8UC1);
  double lo = 0, hi = 0;
  cv::minMaxLoc(aligned, &lo, &hi);
  EXPECT_EQ(lo, 0);
  EXPECT_EQ(hi, 255);
  // The stretch comes from what the visible camera sees (thermal columns ~99..550), not from
  // the whole thermal frame (columns 0..639: counts 3000..3159).
  EXPECT_GT(stats.normalize.low_counts, 3010);
  EXPECT_LT(stats.normalize.high_counts, 3150);
}

TEST(ThermalNormalizer, PercentilesIgnoreHotPixels) {
  cv::Mat counts(100, 100, CV_16UC1);
  for (int r = 0; r < 100; ++r)
    for (int c = 0; c < 100; ++c)
      counts.at<std::uint16_t>(r, c) = static_cast<std::uint16_t>(1000 + c);
  counts.at<std::uint16_t>(5, 5) = 60000;  // a hot pixel
  counts.at<std::uint16_t>(6, 6) = 0;      // a dead one
  ThermalNormalizer normalizer({});
  cv::Mat grey;
  const ThermalNormalizeStats stats = normalizer.normalize(counts, {}, grey);
  EXPECT_EQ(stats.pixels, 10000u);
  // Counts 1000..1099, 100 pixels each (less the two replaced): the 1st percentile (100 pixels)
  // is reached at 1000 (with the dead pixel), the 99th (9900) at 1099.
  EXPECT_EQ(stats.low_counts, 1000);
  EXPECT_EQ(stats.high_counts, 1099);
  EXPECT_EQ(grey.at<std::uint8_t>(50, 0), 0);
  EXPECT_EQ(grey.at<std::uint8_t>(50, 49), std::lround(49 * 255.0 / 99));
  EXPECT_EQ(grey.at<std::uint8_t>(5, 5), 255);
  // Plain min-max would have squeezed the scene into 0.4 grey levels per 100 counts.
}

TEST(ThermalNormalizer, FlatScenesAreNotBlownUp) {
  cv::Mat counts(64, 64, CV_16UC1);
  cv::RNG rng(3);
  rng.fill(counts, cv::RNG::UNIFORM, 5000, 5004);
  ThermalNormalizer normalizer({});
  cv::Mat grey;
  const ThermalNormalizeStats stats = normalizer.normalize(counts, {}, grey);
  EXPECT_EQ(stats.high_counts - stats.low_counts, 48);  // min_span_counts
  double lo = 0, hi = 0;
  cv::minMaxLoc(grey, &lo, &hi);
  EXPECT_LT(hi - lo, 255.0 * 4 / 48 + 1);
}

TEST(ThermalNormalizer, OnlyValidPixelsEnterTheHistogram) {
  cv::Mat counts(10, 10, CV_16UC1, cv::Scalar(2000));
  counts(cv::Rect(0, 0, 10, 5)).setTo(100);  // the invalid half
  cv::Mat valid(10, 10, CV_8UC1, cv::Scalar(255));
  valid(cv::Rect(0, 0, 10, 5)).setTo(0);
  ThermalNormalizer normalizer({});
  cv::Mat grey;
  const ThermalNormalizeStats stats = normalizer.normalize(counts, valid, grey);
  EXPECT_EQ(stats.pixels, 50u);
  EXPECT_GE(stats.low_counts, 2000 - 48);
}

}  // namespace
}  // namespace posed::vision
