#include "core/sync/pose_interpolation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace posed {
// Named rather than anonymous: test binaries build as unity batches, where another file's
// helpers of the same name share the translation unit.
namespace pose_interpolation_test {

HostTime ms(std::int64_t v) { return HostTime::from_ns(Duration::from_ms(v).ns); }

constexpr double kPi = std::numbers::pi;

Eigen::Quaterniond about_z(double angle_rad) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::UnitZ()));
}

Pose pose(std::int64_t stamp_ms, const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  return Pose{ms(stamp_ms), p, q};
}

/// Angle of the rotation taking a to b [rad], sign of the quaternions ignored.
double angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b);
}

TEST(InterpolatePose, SlerpMidpointOfZeroAndNinetyDegreesAboutZIsFortyFive) {
  const Pose a = pose(0, Eigen::Vector3d(0, 0, 0), about_z(0.0));
  const Pose b = pose(100, Eigen::Vector3d(2, -4, 1), about_z(kPi / 2));
  const auto mid = interpolate_pose(a, b, ms(50));
  ASSERT_TRUE(mid.has_value());
  EXPECT_EQ(mid->stamp, ms(50));
  EXPECT_NEAR(angle_between(mid->q, about_z(kPi / 4)), 0.0, 1e-12);
  EXPECT_NEAR((mid->p - Eigen::Vector3d(1, -2, 0.5)).norm(), 0.0, 1e-12);
  // A quarter of the way: 22.5 degrees, a quarter of the translation.
  const auto quarter = interpolate_pose(a, b, ms(25));
  ASSERT_TRUE(quarter.has_value());
  EXPECT_NEAR(angle_between(quarter->q, about_z(kPi / 8)), 0.0, 1e-12);
  EXPECT_NEAR((quarter->p - Eigen::Vector3d(0.5, -1, 0.25)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(mid->q.norm(), 1.0, 1e-12);
}

TEST(InterpolatePose, AntipodalQuaternionTakesTheShortArc) {
  // -q is the same 90-degree rotation; the naive formula would go the long way (270 degrees).
  const Pose a = pose(0, Eigen::Vector3d::Zero(), about_z(0.0));
  Eigen::Quaterniond q_far = about_z(kPi / 2);
  q_far.coeffs() = -q_far.coeffs();
  const Pose b = pose(100, Eigen::Vector3d::Zero(), q_far);
  const auto mid = interpolate_pose(a, b, ms(50));
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR(angle_between(mid->q, about_z(kPi / 4)), 0.0, 1e-12);
  EXPECT_NEAR(angle_between(mid->q, a.q), kPi / 4, 1e-12);

  // Two rotations 170 degrees apart written with opposite signs: still 85 degrees halfway.
  const Pose c = pose(0, Eigen::Vector3d::Zero(), about_z(-0.5));
  Eigen::Quaterniond q_d = about_z(-0.5 + 170.0 * kPi / 180.0);
  q_d.coeffs() = -q_d.coeffs();
  const Pose d = pose(100, Eigen::Vector3d::Zero(), q_d);
  const auto half = interpolate_pose(c, d, ms(50));
  ASSERT_TRUE(half.has_value());
  EXPECT_NEAR(angle_between(half->q, about_z(-0.5 + 85.0 * kPi / 180.0)), 0.0, 1e-12);
}

TEST(InterpolatePose, ExactAtTheEndpoints) {
  const Pose a = pose(10, Eigen::Vector3d(1.25, 2.5, -3.0),
                      Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized());
  const Pose b = pose(20, Eigen::Vector3d(-7.0, 0.5, 3.75),
                      Eigen::Quaterniond(-0.2, 0.7, 0.1, -0.4).normalized());
  const auto at_a = interpolate_pose(a, b, ms(10));
  const auto at_b = interpolate_pose(a, b, ms(20));
  ASSERT_TRUE(at_a && at_b);
  EXPECT_EQ(at_a->p, a.p);
  EXPECT_EQ(at_a->q.coeffs(), a.q.coeffs());
  EXPECT_EQ(at_b->p, b.p);
  EXPECT_EQ(at_b->q.coeffs(), b.q.coeffs());
  // And continuous into them: 1 ns away is within rounding of the endpoint.
  const auto near_b = interpolate_pose(a, b, HostTime::from_ns(ms(20).ns - 1));
  ASSERT_TRUE(near_b.has_value());
  EXPECT_NEAR(angle_between(near_b->q, b.q), 0.0, 1e-6);
  EXPECT_NEAR((near_b->p - b.p).norm(), 0.0, 1e-5);
}

TEST(InterpolatePose, RefusesExtrapolationBeyondTheMargin) {
  const Pose a = pose(0, Eigen::Vector3d(0, 0, 0), about_z(0.0));
  const Pose b = pose(100, Eigen::Vector3d(1, 0, 0), about_z(0.2));
  EXPECT_FALSE(interpolate_pose(a, b, HostTime::from_ns(ms(100).ns + 1)).has_value());
  EXPECT_FALSE(interpolate_pose(a, b, HostTime::from_ns(-1)).has_value());
  const Duration margin = Duration::from_ms(20);
  const auto ahead = interpolate_pose(a, b, ms(120), margin);
  ASSERT_TRUE(ahead.has_value());
  EXPECT_NEAR(ahead->p.x(), 1.2, 1e-12);  // same velocity carried on
  EXPECT_NEAR(angle_between(ahead->q, about_z(0.24)), 0.0, 1e-12);
  const auto behind = interpolate_pose(a, b, ms(-20), margin);
  ASSERT_TRUE(behind.has_value());
  EXPECT_NEAR(behind->p.x(), -0.2, 1e-12);
  EXPECT_NEAR(angle_between(behind->q, about_z(-0.04)), 0.0, 1e-12);
  EXPECT_FALSE(interpolate_pose(a, b, HostTime::from_ns(ms(120).ns + 1), margin).has_value());
  // Bad input: stamps in the wrong order.
  EXPECT_FALSE(interpolate_pose(b, a, ms(50)).has_value());
  // Equal stamps: only that instant (or within the margin), no motion invented.
  EXPECT_TRUE(interpolate_pose(a, a, ms(0)).has_value());
  EXPECT_FALSE(interpolate_pose(a, a, ms(1)).has_value());
  const auto held = interpolate_pose(a, a, ms(5), margin);
  ASSERT_TRUE(held.has_value());
  EXPECT_EQ(held->p, a.p);
}

/// A body turning at 0.5 rad/s about an axis, moving at constant velocity: SLERP and linear
/// interpolation between any two of its poses are exact.
Pose truth(HostTime t) {
  const double s = t.seconds();
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitX()));
  return Pose{t, Eigen::Vector3d(1.0, 2.0, 3.0) + s * Eigen::Vector3d(0.8, -0.3, 0.05),
              q0 * Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * s, axis))};
}

TEST(PoseHistory, AtInterpolatesBetweenHeldPosesOfAConstantRateMotion) {
  PoseHistory history({16, Duration::from_ms(10)});
  EXPECT_FALSE(history.at(ms(0)).has_value());
  for (std::int64_t k = 0; k < 40; ++k) {  // 10 Hz for 4 s; the window keeps the last 16
    ASSERT_TRUE(history.push(truth(ms(100 * k))));
  }
  EXPECT_EQ(history.size(), 16u);
  EXPECT_EQ(history.counters().overwritten, 24u);
  EXPECT_EQ(history[0].stamp, ms(2400));
  for (std::int64_t t_ms = 2390; t_ms <= 3910; t_ms += 7) {
    SCOPED_TRACE(t_ms);
    const auto got = history.at(ms(t_ms));
    ASSERT_TRUE(got.has_value());
    const Pose want = truth(ms(t_ms));
    EXPECT_NEAR((got->p - want.p).norm(), 0.0, 1e-9);
    EXPECT_NEAR(angle_between(got->q, want.q), 0.0, 1e-9);
  }
  EXPECT_FALSE(history.at(ms(2389)).has_value());
  EXPECT_FALSE(history.at(ms(3911)).has_value());
  // Exact on a held pose.
  const auto on = history.at(ms(3000));
  ASSERT_TRUE(on.has_value());
  EXPECT_EQ(on->q.coeffs(), truth(ms(3000)).q.coeffs());
}

TEST(PoseHistory, DropsOutOfOrderPosesAndAnswersFromASinglePose) {
  PoseHistory history({4, Duration::from_ms(0)});
  EXPECT_TRUE(history.push(truth(ms(100))));
  EXPECT_EQ(history.at(ms(100))->p, truth(ms(100)).p);
  EXPECT_FALSE(history.at(ms(101)).has_value());
  EXPECT_FALSE(history.push(truth(ms(50))));
  EXPECT_FALSE(history.push(truth(ms(100))));
  EXPECT_EQ(history.counters().out_of_order_dropped, 2u);
  EXPECT_EQ(history.size(), 1u);
}

}  // namespace pose_interpolation_test
}  // namespace posed
