#include "core/lidar/map_cloud.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace posed::lidar {
namespace map_cloud_test {

ScanPoint at(float x, float y, float z) {
  ScanPoint p;
  p.p = {x, y, z};
  return p;
}

TEST(MapCloud, PointsInOneVoxelMergeIntoTheirCentroidAtTheKeyframePose) {
  MapCloud map(0.5);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(10, 0, 0);
  T.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // Lidar (1.1, 0.1, 0.1) and (1.3, 0.3, 0.3) -> map (9.9, 1.1, 0.1) and (9.7, 1.3, 0.3): one
  // voxel of 0.5 m ([9.5, 10) x [1, 1.5) x [0, 0.5)); a third point lies in another.
  const std::vector<ScanPoint> scan = {at(1.1f, 0.1f, 0.1f), at(1.3f, 0.3f, 0.3f),
                                       at(-3.0f, 0.2f, 0.2f)};
  map.add(scan, T);
  EXPECT_EQ(map.voxels(), 2u);
  std::vector<Eigen::Vector3f> out;
  map.collect(out);
  ASSERT_EQ(out.size(), 2u);
  bool found_centroid = false, found_far = false;
  for (const auto& p : out) {
    if ((p - Eigen::Vector3f(9.8f, 1.2f, 0.2f)).norm() < 1e-5f) found_centroid = true;
    if ((p - Eigen::Vector3f(9.8f, -3.0f, 0.2f)).norm() < 1e-5f) found_far = true;
  }
  EXPECT_TRUE(found_centroid);
  EXPECT_TRUE(found_far);
}

TEST(MapCloud, RevisitingAPlaceDoesNotGrowTheMapAndNegativeCoordinatesPack) {
  MapCloud map(0.2);
  std::vector<ScanPoint> wall;
  for (int i = -50; i < 50; ++i) {
    for (int k = 0; k < 10; ++k)
      wall.push_back(
          at(-5.0f, 0.2f * static_cast<float>(i) + 0.1f, 0.2f * static_cast<float>(k) + 0.1f));
  }
  map.add(wall, Eigen::Isometry3d::Identity());
  const std::size_t once = map.voxels();
  EXPECT_EQ(once, wall.size());  // one point per 0.2 m cell, negative x and y included
  for (int pass = 0; pass < 5; ++pass) map.add(wall, Eigen::Isometry3d::Identity());
  EXPECT_EQ(map.voxels(), once);
}

TEST(MapCloud, CollectIsInAStableOrderWhateverTheInsertionOrder) {
  std::vector<ScanPoint> scan;
  for (int i = 0; i < 200; ++i) {
    scan.push_back(at(static_cast<float>(i % 7) - 3.0f, static_cast<float>(i % 11) - 5.0f,
                      static_cast<float>(i % 3)));
  }
  MapCloud forward(0.5), backward(0.5);
  forward.add(scan, Eigen::Isometry3d::Identity());
  std::vector<ScanPoint> reversed(scan.rbegin(), scan.rend());
  backward.add(reversed, Eigen::Isometry3d::Identity());
  std::vector<Eigen::Vector3f> a, b;
  forward.collect(a);
  backward.collect(b);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i].isApprox(b[i])) << i;
}

}  // namespace map_cloud_test
}  // namespace posed::lidar
