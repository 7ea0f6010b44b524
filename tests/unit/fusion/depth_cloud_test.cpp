// The stacked lidar points the camera front end associates depth with.

#include "core/fusion/depth_cloud.hpp"

#include <gtest/gtest.h>

namespace posed::fusion {
namespace {

std::vector<lidar::ScanPoint> points(std::initializer_list<Eigen::Vector3f> ps) {
  std::vector<lidar::ScanPoint> out;
  for (const auto& p : ps) {
    lidar::ScanPoint s;
    s.p = p;
    out.push_back(s);
  }
  return out;
}

TEST(DepthCloud, PointsInFrontOfTheCameraWithinTheWindowComeOutInTheCameraFrame) {
  DepthCloud cloud(DepthCloudConfig{.window = Duration::from_ms(1000),
                                    .max_points_per_scan = 100,
                                    .view_axis_lidar = Eigen::Vector3d::UnitX()});
  Eigen::Isometry3d T_map_lidar = Eigen::Isometry3d::Identity();
  T_map_lidar.translation() = Eigen::Vector3d(10, 0, 0);
  // One point in front (x > 0), one behind: only the first is kept.
  const auto scan = points({{5, 1, 0}, {-5, 0, 0}});
  cloud.add_scan(HostTime::from_ns(1'000'000'000), T_map_lidar, scan);
  // The camera at the map origin looking along map +x (camera z = map x, x = -map y, y = -map z).
  Eigen::Isometry3d T_map_cam = Eigen::Isometry3d::Identity();
  T_map_cam.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  std::vector<Eigen::Vector3f> out;
  cloud.points_in_camera(HostTime::from_ns(1'500'000'000), T_map_cam, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].z(), 15.f, 1e-5f);  // map x 15
  EXPECT_NEAR(out[0].x(), -1.f, 1e-5f);  // map y 1 is camera -x
  EXPECT_NEAR(out[0].y(), 0.f, 1e-5f);
  // A frame more than the window after the scan: the scan has gone.
  cloud.points_in_camera(HostTime::from_ns(2'100'000'000), T_map_cam, out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(cloud.scans(), 0u);
}

TEST(DepthCloud, ABigScanIsThinnedEvenlyToTheBound) {
  DepthCloud cloud(DepthCloudConfig{.window = Duration::from_ms(1000),
                                    .max_points_per_scan = 1000,
                                    .view_axis_lidar = Eigen::Vector3d::UnitX()});
  std::vector<lidar::ScanPoint> scan;
  for (int i = 0; i < 10'000; ++i) {
    lidar::ScanPoint p;
    p.p = Eigen::Vector3f(1.f + 0.001f * static_cast<float>(i), 0, 0);
    scan.push_back(p);
  }
  cloud.add_scan(HostTime::from_ns(0), Eigen::Isometry3d::Identity(), scan);
  std::vector<Eigen::Vector3f> out;
  cloud.points_in_camera(HostTime::from_ns(1), Eigen::Isometry3d::Identity(), out);
  ASSERT_EQ(out.size(), 1000u);
  // Evenly: the kept points span the whole scan.
  EXPECT_NEAR(out.front().x(), 1.f, 1e-6f);
  EXPECT_NEAR(out.back().x(), 1.f + 0.001f * 9990, 1e-3f);
}

}  // namespace
}  // namespace posed::fusion
