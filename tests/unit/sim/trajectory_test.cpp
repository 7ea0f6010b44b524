// The trajectory's closed-form derivatives against finite differences of its own position and
// orientation, on every scenario's drive (turns, stops, ramps and bumps).

#include <gtest/gtest.h>

#include <string>

#include "tools/sim/scenarios.hpp"

namespace posed::sim {
namespace {

TEST(Trajectory, DerivativesMatchFiniteDifferences) {
  for (std::string_view name : scenario_names()) {
    std::string error;
    auto s = make_scenario(name, 7, 60.0, 9.805, error);
    ASSERT_TRUE(s) << error;
    const Trajectory& tr = s->trajectory;
    const double h = 1e-4;
    double max_v = 0, max_a = 0, max_w = 0, max_f = 0;
    for (double t = 0.5; t < 60.0; t += 0.37) {
      const TrajectorySample a = tr.at(t - h), b = tr.at(t), c = tr.at(t + h);
      const Eigen::Vector3d v_fd = (c.p_map_base_m - a.p_map_base_m) / (2 * h);
      const Eigen::Vector3d a_fd = (c.v_map_mps - a.v_map_mps) / (2 * h);
      // ω_base = log(R(t-h)^T R(t+h)) / 2h
      const Eigen::AngleAxisd dq(a.q_map_base.conjugate() * c.q_map_base);
      const Eigen::Vector3d w_fd = dq.axis() * dq.angle() / (2 * h);
      const Eigen::Vector3d f_expect =
          b.q_map_base.conjugate() * (a_fd + Eigen::Vector3d(0, 0, 9.805));
      max_v = std::max(max_v, (v_fd - b.v_map_mps).norm());
      max_a = std::max(max_a, (a_fd - b.a_map_mps2).norm());
      max_w = std::max(max_w, (w_fd - b.w_base_radps).norm());
      max_f = std::max(max_f, (f_expect - b.f_base_mps2).norm());
    }
    EXPECT_LT(max_v, 1e-5) << name;
    EXPECT_LT(max_a, 1e-4) << name;
    EXPECT_LT(max_w, 1e-5) << name;
    EXPECT_LT(max_f, 1e-4) << name;
  }
}

TEST(Trajectory, StartsStillThenMovesStopsAndTurns) {
  std::string error;
  auto s = make_scenario("street_night", 3, 120.0, 9.805, error);
  ASSERT_TRUE(s) << error;
  const Trajectory& tr = s->trajectory;
  // Static start for gravity alignment: exactly zero motion, specific force = +g up.
  const TrajectorySample t0 = tr.at(1.0);
  EXPECT_EQ(t0.v_map_mps.norm(), 0.0);
  EXPECT_EQ(t0.w_base_radps.norm(), 0.0);
  EXPECT_NEAR(t0.f_base_mps2.z(), 9.805, 1e-12);
  double max_speed = 0, max_yaw_rate = 0, max_accel = 0;
  bool stopped_later = false;
  for (double t = 3.0; t < 120.0; t += 0.05) {
    const TrajectorySample x = tr.at(t);
    const double v = x.v_map_mps.head<2>().norm();
    max_speed = std::max(max_speed, v);
    max_yaw_rate = std::max(max_yaw_rate, std::abs(x.w_base_radps.z()));
    max_accel = std::max(max_accel, x.a_map_mps2.head<2>().norm());
    stopped_later = stopped_later || (t > 10 && v < 1e-9);
  }
  EXPECT_GT(max_speed, 2.0);
  EXPECT_GT(max_yaw_rate, 0.05);
  EXPECT_GT(max_accel, 0.2);
  EXPECT_LT(max_accel, 5.0);
  EXPECT_TRUE(stopped_later);
}

TEST(PeriodicSpline, IsClosedAndC2) {
  PeriodicSpline2 sp({{0, 0}, {10, 1}, {12, 8}, {3, 9}, {-2, 4}});
  Eigen::Vector2d p0, d10, d20, d3, p1, d11, d21;
  sp.eval(0.0, p0, d10, d20, d3);
  sp.eval(sp.length() - 1e-9, p1, d11, d21, d3);
  EXPECT_LT((p0 - p1).norm(), 1e-6);
  EXPECT_LT((d10 - d11).norm(), 1e-6);
  EXPECT_LT((d20 - d21).norm(), 1e-6);
  EXPECT_LT((p0 - Eigen::Vector2d(0, 0)).norm(), 1e-12);  // interpolates the waypoints
}

}  // namespace
}  // namespace posed::sim
