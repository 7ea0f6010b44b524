#include "core/mapping/pose_graph.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tests/unit/mapping/synthetic_scene.hpp"

namespace posed::mapping {
namespace {

using test::pose;

/// A 20 x 10 m rectangle driven once, a node every metre: the truth.
std::vector<Eigen::Isometry3d> rectangle() {
  std::vector<Eigen::Isometry3d> truth;
  double x = 0, y = 0, yaw = 0;
  for (const auto& [length, turn] : {std::pair{20, 1}, {10, 1}, {20, 1}, {10, 0}}) {
    for (int i = 0; i < length; ++i) {
      truth.push_back(pose(x, y, 0, yaw));
      x += std::cos(yaw);
      y += std::sin(yaw);
    }
    yaw += turn * std::numbers::pi / 2;
  }
  truth.push_back(pose(x, y, 0, yaw));  // back at the start
  return truth;
}

TEST(PoseGraph, ALoopEdgeTakesOutTheOdometrysDrift) {
  const auto truth = rectangle();
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  PoseGraph graph;
  Eigen::Isometry3d dead_reckoning = truth[0];
  graph.add_node(dead_reckoning);
  for (std::size_t i = 1; i < truth.size(); ++i) {
    // Odometry with a steady yaw bias (0.6 degrees per metre) and noise.
    Eigen::Isometry3d step = truth[i - 1].inverse() * truth[i];
    step = step * pose(0.01 * noise(rng), 0.01 * noise(rng), 0, 0.01 + 0.002 * noise(rng));
    dead_reckoning = dead_reckoning * step;
    graph.add_node(dead_reckoning);
    graph.add_edge({.from = i - 1,
                    .to = i,
                    .T_from_to = step,
                    .sigma_translation_m = 0.02,
                    .sigma_rotation_rad = 0.01});
  }
  const std::size_t last = truth.size() - 1;
  const double drift_before = (graph.node(last).translation() - truth[last].translation()).norm();
  ASSERT_GT(drift_before, 1.0);
  // The loop: the last pose is where the first one was.
  graph.add_edge({.from = 0,
                  .to = last,
                  .T_from_to = truth[0].inverse() * truth[last],
                  .sigma_translation_m = 0.02,
                  .sigma_rotation_rad = 0.005,
                  .loop = true});
  const PoseGraphSolve solve = graph.optimise();
  EXPECT_TRUE(solve.converged);
  EXPECT_LT(solve.final_cost, solve.initial_cost);
  double worst = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    worst = std::max(worst, (graph.node(i).translation() - truth[i].translation()).norm());
  }
  EXPECT_LT((graph.node(last).translation() - truth[last].translation()).norm(), 0.1);
  EXPECT_LT(worst, 0.3 * drift_before) << "drift before " << drift_before;
  // The first node is the map's anchor.
  EXPECT_TRUE(graph.node(0).isApprox(truth[0], 1e-12));
  EXPECT_LT(graph.whitened_residual(graph.edges().back()).norm(), 3.0);
}

TEST(PoseGraph, ConsistentEdgesLeaveTheirNodesAtTheAnswer) {
  PoseGraph graph;
  const Eigen::Isometry3d a = pose(1, 2, 0.5, 0.3), b = pose(4, -1, 0.7, -1.2);
  graph.add_node(a);
  graph.add_node(b * pose(0.5, 0.5, 0, 0.2));  // a wrong initial value
  graph.add_edge({.from = 0, .to = 1, .T_from_to = a.inverse() * b});
  graph.optimise();
  EXPECT_TRUE(graph.node(1).isApprox(b, 1e-6));
  EXPECT_LT(graph.whitened_residual(graph.edges()[0]).norm(), 1e-5);
}

TEST(PoseGraph, RefusesEdgesToMissingNodes) {
  PoseGraph graph;
  graph.add_node(Eigen::Isometry3d::Identity());
  EXPECT_THROW(graph.add_edge({.from = 0, .to = 1}), std::invalid_argument);
  EXPECT_THROW(graph.add_edge({.from = 0, .to = 0}), std::invalid_argument);
}

}  // namespace
}  // namespace posed::mapping
