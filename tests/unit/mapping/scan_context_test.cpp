#include "core/mapping/scan_context.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "tests/unit/mapping/synthetic_scene.hpp"

namespace posed::mapping {
namespace {

using test::pose;

/// What a sensor at `T_world_sensor` (1.5 m up) sees within 40 m, in its own levelled frame.
std::vector<Eigen::Vector3f> seen_from(const std::vector<Eigen::Vector3f>& world,
                                       const Eigen::Isometry3d& T_world_sensor) {
  std::vector<Eigen::Vector3f> out;
  const Eigen::Isometry3f T_sensor_world = T_world_sensor.inverse().cast<float>();
  for (const Eigen::Vector3f& p : world) {
    const Eigen::Vector3f q = T_sensor_world * p;
    if (q.head<2>().norm() < 40.f) {
      out.push_back(q);
    }
  }
  return out;
}

std::vector<test::Box> town() {
  std::vector<test::Box> boxes;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-60.f, 60.f), size(1.f, 8.f), height(1.f, 15.f);
  for (int i = 0; i < 80; ++i) {
    const float x = u(rng), y = u(rng), sx = size(rng), sy = size(rng);
    boxes.push_back({{x, y, 0}, {x + sx, y + sy, height(rng)}});
  }
  return boxes;
}

TEST(ScanContext, MatchesTheSamePlaceSeenWithAnotherHeadingAndGivesTheYaw) {
  const auto world = test::sample_boxes(town(), 0.5f);
  const ScanContextConfig config;
  const double yaw = 1.3;  // 74.5 degrees
  const ScanContext a = make_scan_context(seen_from(world, pose(0, 0, 1.5, 0.0)), config);
  const ScanContext b = make_scan_context(seen_from(world, pose(0.3, 0.2, 1.5, yaw)), config);
  const ScanContextMatch m = match_scan_contexts(b, a, config);
  EXPECT_LT(m.distance, 0.15);
  const double sector = 2 * std::numbers::pi / config.sectors;
  EXPECT_NEAR(m.yaw_rad, yaw, 1.5 * sector);
  // The ring key does not depend on heading.
  EXPECT_LT((a.ring_key - b.ring_key).norm(), 0.2 * a.ring_key.norm());
}

TEST(ScanContext, TellsAnotherPlaceApart) {
  const auto world = test::sample_boxes(town(), 0.5f);
  const ScanContextConfig config;
  const ScanContext a = make_scan_context(seen_from(world, pose(0, 0, 1.5, 0.0)), config);
  const ScanContext same = make_scan_context(seen_from(world, pose(0.2, 0, 1.5, 0.5)), config);
  const ScanContext other = make_scan_context(seen_from(world, pose(35, -30, 1.5, 0.0)), config);
  const double d_same = match_scan_contexts(same, a, config).distance;
  const double d_other = match_scan_contexts(other, a, config).distance;
  EXPECT_GT(d_other, 0.3);
  EXPECT_GT(d_other, 2.5 * d_same);
}

TEST(ScanContext, EmptyScansMatchNothing) {
  const ScanContextConfig config;
  const ScanContext empty = make_scan_context({}, config);
  EXPECT_EQ(empty.bins.rows(), config.rings);
  EXPECT_EQ(empty.bins.cols(), config.sectors);
  EXPECT_DOUBLE_EQ(match_scan_contexts(empty, empty, config).distance, 1.0);
}

}  // namespace
}  // namespace posed::mapping
