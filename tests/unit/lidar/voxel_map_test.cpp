// The local map's confirmation of what stays (VoxelMapConfig::confirm_after_s): a wall scanned
// again and again is matched against; the trail of something walking through it is not, and
// gives its places in a full voxel to what comes after it.

#include "core/lidar/voxel_map.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace posed::lidar {
namespace {

constexpr std::int64_t kScanNs = 100'000'000;  // 10 Hz

/// A scan's points on the wall x = 5 (y, z in [0, 2) m, a new 0.1 m grid offset per scan, as a
/// spinning lidar's rings fall elsewhere each time) and a walker's front at x = 2 + 0.12 m per
/// scan (1.2 m/s), y in [0, 0.4) m.
std::vector<Eigen::Vector3f> scan(int k) {
  std::vector<Eigen::Vector3f> out;
  const float jitter = 0.03f * static_cast<float>(k % 3);
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) {
      out.emplace_back(5.f, 0.1f * static_cast<float>(i) + jitter,
                       0.1f * static_cast<float>(j) + jitter);
    }
  }
  const float walker_x = 2.f + 0.12f * static_cast<float>(k);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 10; ++j) {
      out.emplace_back(walker_x, 0.1f * static_cast<float>(i), 0.1f * static_cast<float>(j) + 0.5f);
    }
  }
  return out;
}

int near_count(const VoxelMap& map, const Eigen::Vector3f& query) {
  Eigen::Vector3f out[5];
  return map.nearest(query, 5, 0.3f, out);
}

TEST(VoxelMapConfirmation, TheWallIsMatchedTheWalkersTrailIsNot) {
  VoxelMap map({1.0, 20, 0.05, 1.0});
  for (int k = 0; k < 30; ++k) map.insert(scan(k), k * kScanNs);  // 3 s
  EXPECT_EQ(near_count(map, {5.f, 1.f, 1.f}), 5) << "the wall, found again every scan";
  // Where the walker was at 1.2-1.8 s (x 3.4-4.2 m): seen once, never found again.
  EXPECT_EQ(near_count(map, {3.8f, 0.2f, 0.9f}), 0) << "the walker's trail";
  EXPECT_LT(map.confirmed_points(), map.points());
  std::vector<Eigen::Vector3f> exported;
  map.collect(exported);
  EXPECT_EQ(exported.size(), map.confirmed_points());
  for (const Eigen::Vector3f& p : exported) EXPECT_NEAR(p.x(), 5.f, 1e-4f) << "only the wall";
}

TEST(VoxelMapConfirmation, AYoungMapMatchesEverythingAndWithoutItEveryPointCountsAtOnce) {
  VoxelMap young({1.0, 20, 0.05, 1.0});
  for (int k = 0; k < 5; ++k) young.insert(scan(k), k * kScanNs);  // 0.4 s: younger than 1 s
  EXPECT_EQ(near_count(young, {2.24f, 0.2f, 0.9f}), 5) << "the walker at 0.2 s, still used";

  VoxelMap plain({1.0, 20, 0.05, 0.0});
  for (int k = 0; k < 30; ++k) plain.insert(scan(k), k * kScanNs);
  EXPECT_EQ(near_count(plain, {3.8f, 0.2f, 0.9f}), 5) << "no confirmation: the trail counts";
  EXPECT_EQ(plain.confirmed_points(), plain.points());
}

TEST(VoxelMapConfirmation, WhatPassedThroughAFullVoxelGivesItsPlaceToWhatCameAfter) {
  // One voxel, 4 points at most: a walker fills it at 0 s; from 2 s (twice the span) on, points
  // of the wall that stands there after take its places.
  VoxelMap map({1.0, 4, 0.05, 1.0});
  std::vector<Eigen::Vector3f> walker = {
      {0.1f, 0.1f, 0.1f}, {0.1f, 0.3f, 0.1f}, {0.1f, 0.5f, 0.1f}, {0.1f, 0.7f, 0.1f}};
  map.insert(walker, 0);
  std::vector<Eigen::Vector3f> wall = {
      {0.9f, 0.1f, 0.5f}, {0.9f, 0.3f, 0.5f}, {0.9f, 0.5f, 0.5f}, {0.9f, 0.7f, 0.5f}};
  for (int k = 5; k <= 40; ++k) map.insert(wall, k * kScanNs);
  std::vector<Eigen::Vector3f> kept;
  map.collect(kept);
  ASSERT_EQ(kept.size(), 4u) << "the wall's points, confirmed";
  for (const Eigen::Vector3f& p : kept) EXPECT_NEAR(p.x(), 0.9f, 1e-4f);
  EXPECT_EQ(map.points(), 4u);
}

TEST(VoxelMap, ForgetsWhatIsOutOfReachAndReusesItsPlaces) {
  // A drive along x: a 2 m x 2 m patch of points every metre; behind the robot the map is cut
  // at 10 m, as LidarOdometry does. What stays must be found as before, what went must not be.
  VoxelMap map({1.0, 20, 0.05, 0.0});
  const auto patch = [](float x0) {
    std::vector<Eigen::Vector3f> out;
    for (int i = 0; i < 10; ++i) {
      for (int j = 0; j < 10; ++j) {
        out.emplace_back(x0 + 0.1f * static_cast<float>(i), 0.2f * static_cast<float>(j), 0.5f);
      }
    }
    return out;
  };
  std::size_t most_voxels = 0;
  for (int x = 0; x < 200; ++x) {
    map.insert(patch(static_cast<float>(x)), x * kScanNs);
    map.remove_far_from({static_cast<float>(x), 1.f, 0.5f}, 10.0);
    most_voxels = std::max(most_voxels, map.voxels());
    Eigen::Vector3f out[5];
    ASSERT_EQ(map.nearest({static_cast<float>(x) + 0.45f, 1.f, 0.5f}, 5, 0.5f, out), 5) << x;
    if (x >= 20) {
      EXPECT_EQ(map.nearest({static_cast<float>(x - 15) + 0.45f, 1.f, 0.5f}, 5, 0.5f, out), 0)
          << "forgotten at " << x;
    }
  }
  EXPECT_LE(most_voxels, 24u) << "the map follows the robot";
  std::vector<Eigen::Vector3f> kept;
  map.collect(kept);
  EXPECT_EQ(kept.size(), map.points());
  for (const Eigen::Vector3f& p : kept) EXPECT_GT(p.x(), 199.f - 11.f);
}

}  // namespace
}  // namespace posed::lidar
