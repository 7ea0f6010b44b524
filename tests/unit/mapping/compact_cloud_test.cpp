// The keyframe clouds the mapping layer keeps for a whole run, at 6 bytes a point.

#include "core/mapping/compact_cloud.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace posed::mapping {
namespace {

TEST(CompactCloud, KeepsEveryPointWithinHalfAStepInHalfTheBytes) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coordinate(-60.0f, 60.0f);
  std::vector<Eigen::Vector3f> points(5000);
  for (Eigen::Vector3f& p : points) p = {coordinate(rng), coordinate(rng), coordinate(rng)};
  const CompactCloud cloud(points);
  ASSERT_EQ(cloud.size(), points.size());
  float worst = 0;
  std::size_t i = 0;
  for (const Eigen::Vector3f& p : cloud) {  // iteration and indexing agree
    EXPECT_EQ(p, cloud[i]);
    worst = std::max(worst, (p - points[i]).cwiseAbs().maxCoeff());
    ++i;
  }
  EXPECT_EQ(i, points.size());
  EXPECT_LE(worst, CompactCloud::kResolutionM / 2 + 1e-5f);  // float's own rounding at 60 m
  EXPECT_GT(worst, CompactCloud::kResolutionM / 4);          // it does quantise
  EXPECT_EQ(cloud.points().size(), points.size());
  EXPECT_EQ(cloud.bytes(), points.size() * 6);
}

TEST(CompactCloud, SaysWhichPointsItCannotHoldAndNeverWrapsOne) {
  EXPECT_TRUE(CompactCloud::fits({131.0f, -131.0f, 0.0f}));
  EXPECT_FALSE(CompactCloud::fits({0.0f, 132.0f, 0.0f}));
  EXPECT_FALSE(CompactCloud::fits({std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f}));
  EXPECT_FALSE(CompactCloud::fits({std::numeric_limits<float>::infinity(), 0.0f, 0.0f}));
  // Pushed regardless: clamped to the edge, not wrapped to the other side.
  CompactCloud cloud;
  cloud.push_back({500.0f, -500.0f, 1.0f});
  EXPECT_NEAR(cloud[0].x(), CompactCloud::kReachM, 1e-3f);
  EXPECT_NEAR(cloud[0].y(), -CompactCloud::kReachM, 1e-3f);
  EXPECT_NEAR(cloud[0].z(), 1.0f, CompactCloud::kResolutionM);
}

}  // namespace
}  // namespace posed::mapping
