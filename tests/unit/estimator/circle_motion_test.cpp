#include "core/sim/circle_motion.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace posed::sim {
namespace {

TEST(CircleMotion, StaticThenOnTheCircle) {
  CircleMotion motion(
      {.radius_m = 5, .speed_mps = 1, .static_s = 2, .ramp_s = 3, .gravity_mps2 = 9.8});
  const auto rest = motion.at(Duration::from_s(1));
  EXPECT_EQ(rest.p_map_base_m.norm(), 0.0);
  EXPECT_EQ(rest.f_base_mps2, Eigen::Vector3d(0, 0, 9.8));
  for (int s = 0; s < 60; ++s) {
    const auto m = motion.at(Duration::from_s(s));
    EXPECT_NEAR((m.p_map_base_m - Eigen::Vector3d(0, 5, 0)).norm(), 5.0, 1e-12);
  }
  const auto cruise = motion.at(Duration::from_s(10));
  EXPECT_NEAR(cruise.v_map_mps.norm(), 1.0, 1e-12);
  EXPECT_NEAR(cruise.w_base_radps.z(), 0.2, 1e-12);
  EXPECT_NEAR(cruise.f_base_mps2.y(), 0.2, 1e-12);  // v^2 / R
}

TEST(CircleMotion, VelocityIsTheDerivativeOfPosition) {
  CircleMotion motion({});
  for (double t : {2.5, 3.7, 4.9, 8.0}) {
    const double h = 1e-5;
    const auto a = motion.at(Duration::from_seconds(t - h));
    const auto b = motion.at(Duration::from_seconds(t + h));
    const Eigen::Vector3d v_numeric = (b.p_map_base_m - a.p_map_base_m) / (2 * h);
    EXPECT_NEAR((v_numeric - motion.at(Duration::from_seconds(t)).v_map_mps).norm(), 0, 1e-5) << t;
  }
}

}  // namespace
}  // namespace posed::sim
