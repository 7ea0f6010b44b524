// IMU-rate odometry from the back end's anchors: it follows the motion from an anchor, takes a
// late anchor forward through the IMU it holds, and blends a correction out without a jump larger
// than the correction (or applies a large one at once).

#include "core/estimator/odometry_propagator.hpp"

#include <gtest/gtest.h>

#include "tests/unit/estimator/analytic_motion.hpp"

namespace posed::estimator {
namespace {

constexpr double kRateHz = 200.0;

NavState truth_anchor(const test::AnalyticMotion& m, double t) {
  NavState a;
  a.stamp = m.sample(t).stamp;
  a.p_map_base_m = m.p(t);
  a.q_map_base = Eigen::Quaterniond(m.R(t));
  a.v_map_mps = m.v(t);
  a.anchor = true;
  a.optimised = true;
  a.mode = EstimatorMode::kLidarInertial;
  return a;
}

OdometryPropagatorConfig config_for(const test::AnalyticMotion& m) {
  OdometryPropagatorConfig c;
  c.gravity_mps2 = m.gravity_mps2;
  return c;
}

TEST(OdometryPropagator, NothingBeforeTheFirstAnchor) {
  const test::AnalyticMotion m;
  OdometryPropagator odom(config_for(m));
  NavState out;
  for (int i = 0; i < 10; ++i) EXPECT_FALSE(odom.add_imu(m.sample(i / kRateHz), out));
  EXPECT_FALSE(odom.has_anchor());
}

TEST(OdometryPropagator, FollowsTheMotionFromAnAnchor) {
  const test::AnalyticMotion m;
  OdometryPropagator odom(config_for(m));
  odom.set_anchor(truth_anchor(m, 0.0));
  NavState out;
  int published = 0;
  for (int i = 0; i <= 200; ++i) {  // 1 s
    if (odom.add_imu(m.sample(i / kRateHz), out)) ++published;
  }
  EXPECT_EQ(published, 200);  // every sample after the anchor's
  EXPECT_EQ(out.stamp, m.sample(1.0).stamp);
  EXPECT_LT((out.p_map_base_m - m.p(1.0)).norm(), 2e-3);
  EXPECT_LT(out.q_map_base.angularDistance(Eigen::Quaterniond(m.R(1.0))), 1e-4);
  EXPECT_LT((out.v_map_mps - m.v(1.0)).norm(), 5e-3);
  EXPECT_FALSE(out.optimised);
  EXPECT_EQ(out.mode, EstimatorMode::kLidarInertial);
}

TEST(OdometryPropagator, ALateAnchorIsCarriedForwardThroughTheHeldSamples) {
  const test::AnalyticMotion m;
  OdometryPropagator odom(config_for(m));
  // A wrong start: 0.3 m and 0.1 rad off, as the odometry a back end later corrects.
  NavState wrong = truth_anchor(m, 0.0);
  wrong.p_map_base_m += Eigen::Vector3d(0.3, 0, 0);
  odom.set_anchor(wrong);
  NavState out;
  for (int i = 0; i <= 200; ++i) odom.add_imu(m.sample(i / kRateHz), out);
  // The back end's state for t = 0.6 s lands at t = 1 s (a scan match's delay).
  odom.set_anchor(truth_anchor(m, 0.6));
  EXPECT_NEAR(odom.figures().last_correction_m, 0.3, 0.01);
  EXPECT_EQ(odom.figures().snaps, 0u);
  for (int i = 201; i <= 240; ++i) odom.add_imu(m.sample(i / kRateHz), out);  // 0.2 s > blend
  EXPECT_LT((out.p_map_base_m - m.p(1.2)).norm(), 2e-3);
  EXPECT_LT(out.q_map_base.angularDistance(Eigen::Quaterniond(m.R(1.2))), 1e-4);
}

TEST(OdometryPropagator, ACorrectionIsBlendedOutWithoutAJumpLargerThanItself) {
  const test::AnalyticMotion m;
  OdometryPropagatorConfig c = config_for(m);
  c.blend_s = 0.1;
  OdometryPropagator odom(c);
  NavState wrong = truth_anchor(m, 0.0);
  wrong.p_map_base_m += Eigen::Vector3d(0.0, 0.2, 0.0);
  odom.set_anchor(wrong);
  NavState out, previous;
  for (int i = 0; i <= 200; ++i) odom.add_imu(m.sample(i / kRateHz), out);
  previous = out;
  odom.set_anchor(truth_anchor(m, 0.9));
  const double correction = odom.figures().last_correction_m;
  ASSERT_NEAR(correction, 0.2, 0.01);
  // Per step: the IMU's own motion plus at most correction x (5 ms / 100 ms).
  double largest_extra_m = 0;
  for (int i = 201; i <= 260; ++i) {
    const double t = i / kRateHz;
    ASSERT_TRUE(odom.add_imu(m.sample(t), out));
    const Eigen::Vector3d own = m.p(t) - m.p(t - 1 / kRateHz);
    const double extra = (out.p_map_base_m - previous.p_map_base_m - own).norm();
    largest_extra_m = std::max(largest_extra_m, extra);
    previous = out;
  }
  EXPECT_LE(largest_extra_m, correction * (1 / kRateHz) / c.blend_s + 1e-3);
  EXPECT_GT(largest_extra_m, 0.5 * correction * (1 / kRateHz) / c.blend_s);  // it did move
  EXPECT_LT((out.p_map_base_m - m.p(1.3)).norm(), 2e-3);                     // and arrived
}

TEST(OdometryPropagator, ACorrectionTooLargeToBlendIsAppliedAtOnce) {
  const test::AnalyticMotion m;
  OdometryPropagatorConfig c = config_for(m);
  c.snap_m = 1.0;
  OdometryPropagator odom(c);
  NavState wrong = truth_anchor(m, 0.0);
  wrong.p_map_base_m += Eigen::Vector3d(3.0, 0, 0);  // a re-initialisation's correction
  odom.set_anchor(wrong);
  NavState out;
  for (int i = 0; i <= 100; ++i) odom.add_imu(m.sample(i / kRateHz), out);
  odom.set_anchor(truth_anchor(m, 0.4));
  EXPECT_EQ(odom.figures().snaps, 1u);
  ASSERT_TRUE(odom.add_imu(m.sample(101 / kRateHz), out));
  EXPECT_LT((out.p_map_base_m - m.p(101 / kRateHz)).norm(), 2e-3);
}

TEST(OdometryPropagator, AnOlderAnchorThanTheCurrentOneIsIgnored) {
  const test::AnalyticMotion m;
  OdometryPropagator odom(config_for(m));
  odom.set_anchor(truth_anchor(m, 0.5));
  NavState stale = truth_anchor(m, 0.2);
  stale.p_map_base_m += Eigen::Vector3d(1, 1, 1);
  odom.set_anchor(stale);
  EXPECT_EQ(odom.figures().anchors, 1u);
}

TEST(OdometryPropagator, TheCovarianceGrowsFromTheAnchors) {
  const test::AnalyticMotion m;
  OdometryPropagatorConfig c = config_for(m);
  c.accel_noise_density = 0.01;
  c.gyro_noise_density = 0.001;
  OdometryPropagator odom(c);
  NavState a = truth_anchor(m, 0.0);
  a.pose_covariance = Eigen::Matrix<double, 6, 6>::Identity() * 1e-4;
  odom.set_anchor(a);
  NavState out;
  for (int i = 0; i <= 200; ++i) odom.add_imu(m.sample(i / kRateHz), out);
  EXPECT_NEAR(out.pose_covariance(0, 0), 1e-4 + 0.01 * 0.01 / 3.0, 1e-9);
  EXPECT_NEAR(out.pose_covariance(3, 3), 1e-4 + 0.001 * 0.001, 1e-9);
}

}  // namespace
}  // namespace posed::estimator
