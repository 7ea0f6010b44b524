#include "core/estimator/strapdown.hpp"

#include <gtest/gtest.h>

#include <random>

#include "core/sim/circle_motion.hpp"

namespace posed {
namespace {

constexpr double kG = 9.805;

ImuSample sample_at(const sim::CircleMotion& motion, std::int64_t t_ns, std::int64_t t0_ns = 0) {
  const auto m = motion.at(Duration::from_ns(t_ns));
  ImuSample s;
  s.stamp = HostTime::from_ns(t0_ns + t_ns);
  s.angular_velocity_radps = m.w_base_radps;
  s.specific_force_mps2 = m.f_base_mps2;
  return s;
}

TEST(Strapdown, FollowsTheCircleFromExactSamples) {
  const sim::CircleMotion motion(
      {.radius_m = 5, .speed_mps = 1, .static_s = 2, .ramp_s = 3, .gravity_mps2 = kG});
  Strapdown strapdown({.gravity_mps2 = kG});
  const std::int64_t period_ns = 5'000'000;    // 200 Hz
  const std::int64_t t0_ns = 123'456'789'000;  // arbitrary host epoch
  std::optional<NavState> last;
  int states = 0;
  for (std::int64_t t = 0; t <= 20'000'000'000; t += period_ns) {
    if (auto s = strapdown.add(sample_at(motion, t, t0_ns))) {
      last = s;
      ++states;
    }
  }
  ASSERT_TRUE(last.has_value());
  EXPECT_EQ(strapdown.mode(), EstimatorMode::kStrapdown);
  // Alignment takes 1 s of the 2 s static window; everything after is propagated.
  EXPECT_NEAR(states, 19 * 200 + 1, 2);
  const auto truth = motion.at(last->stamp - HostTime::from_ns(t0_ns));
  EXPECT_LT((last->p_map_base_m - truth.p_map_base_m).norm(), 0.01)
      << last->p_map_base_m.transpose() << " vs " << truth.p_map_base_m.transpose();
  EXPECT_LT(last->q_map_base.angularDistance(truth.q_map_base), 1e-3);
  EXPECT_LT((last->v_map_mps - truth.v_map_mps).norm(), 0.005);
}

TEST(Strapdown, AlignmentLevelsATiltedRigAndEstimatesGyroBias) {
  // Rig pitched 10 deg nose-up and rolled 5 deg, with a gyro bias: the alignment must undo both.
  const Eigen::Quaterniond q_map_base_true = Eigen::AngleAxisd(0.1745, Eigen::Vector3d::UnitY()) *
                                             Eigen::AngleAxisd(0.0873, Eigen::Vector3d::UnitX());
  const Eigen::Vector3d bias(0.002, -0.001, 0.003);
  Strapdown strapdown({.gravity_mps2 = kG});
  std::optional<NavState> first;
  for (int i = 0; i < 400 && !first; ++i) {
    ImuSample s;
    s.stamp = HostTime::from_ns(i * 5'000'000LL);
    s.specific_force_mps2 = q_map_base_true.conjugate() * Eigen::Vector3d(0, 0, kG);
    s.angular_velocity_radps = bias;
    first = strapdown.add(s);
  }
  ASSERT_TRUE(first.has_value());
  const Eigen::Vector3d up_body_est = first->q_map_base.conjugate() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d up_body_true = q_map_base_true.conjugate() * Eigen::Vector3d::UnitZ();
  EXPECT_LT((up_body_est - up_body_true).norm(), 1e-9);
  EXPECT_LT((strapdown.gyro_bias() - bias).norm(), 1e-12);
}

TEST(Strapdown, MotionDuringAlignmentRestartsTheWindow) {
  Strapdown strapdown({.gravity_mps2 = kG, .init_static = Duration::from_ms(500)});
  ImuSample s;
  s.specific_force_mps2 = Eigen::Vector3d(0, 0, kG);
  int i = 0;
  for (; i < 50; ++i) {
    s.stamp = HostTime::from_ns(i * 5'000'000LL);
    EXPECT_FALSE(strapdown.add(s).has_value());
  }
  s.angular_velocity_radps = Eigen::Vector3d(0, 0, 0.5);  // someone turns the robot
  s.stamp = HostTime::from_ns(i++ * 5'000'000LL);
  strapdown.add(s);
  EXPECT_EQ(strapdown.counters().alignment_restarts, 1u);
  s.angular_velocity_radps.setZero();
  std::optional<NavState> st;
  int after = 0;
  while (!st) {
    s.stamp = HostTime::from_ns(i++ * 5'000'000LL);
    st = strapdown.add(s);
    ++after;
  }
  EXPECT_EQ(after, 101);  // a full new window of 500 ms at 200 Hz
}

TEST(Strapdown, OutOfOrderAndGapsAreCountedNotIntegrated) {
  Strapdown strapdown({.gravity_mps2 = kG, .init_static = Duration::from_ms(100)});
  ImuSample s;
  s.specific_force_mps2 = Eigen::Vector3d(0, 0, kG);
  std::int64_t t = 0;
  for (int i = 0; i < 30; ++i, t += 5'000'000) {
    s.stamp = HostTime::from_ns(t);
    strapdown.add(s);
  }
  ASSERT_EQ(strapdown.mode(), EstimatorMode::kStrapdown);
  s.stamp = HostTime::from_ns(t - 20'000'000);
  EXPECT_FALSE(strapdown.add(s).has_value());
  EXPECT_EQ(strapdown.counters().out_of_order, 1u);
  s.stamp = HostTime::from_ns(t + 1'000'000'000);     // 1 s gap
  s.specific_force_mps2 = Eigen::Vector3d(5, 0, kG);  // would move us 2.5 m if integrated
  EXPECT_FALSE(strapdown.add(s).has_value());
  EXPECT_EQ(strapdown.counters().gaps, 1u);
  s.stamp = s.stamp + Duration::from_ms(5);
  s.specific_force_mps2 = Eigen::Vector3d(0, 0, kG);
  auto st = strapdown.add(s);
  ASSERT_TRUE(st.has_value());
  EXPECT_LT(st->p_map_base_m.norm(), 1e-3);
}

TEST(Strapdown, CovarianceGrowsWithNoise) {
  StrapdownConfig cfg{.gravity_mps2 = kG,
                      .init_static = Duration::from_ms(200),
                      .gyro_noise_density = 2.3e-3,
                      .accel_noise_density = 3.8e-2};
  Strapdown strapdown(cfg);
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 1);
  ImuSample s;
  double previous_var = -1;
  for (int i = 0; i < 2000; ++i) {
    s.stamp = HostTime::from_ns(i * 5'000'000LL);
    s.specific_force_mps2 =
        Eigen::Vector3d(0, 0, kG) + 0.5 * Eigen::Vector3d(n(rng), n(rng), n(rng));
    s.angular_velocity_radps = 0.03 * Eigen::Vector3d(n(rng), n(rng), n(rng));
    if (auto st = strapdown.add(s); st && i % 200 == 0) {
      const double var = st->pose_covariance(0, 0);
      EXPECT_GT(var, previous_var);
      previous_var = var;
      EXPECT_TRUE(st->pose_covariance.isApprox(st->pose_covariance.transpose()));
    }
  }
  EXPECT_GT(previous_var, 0.0);
}

}  // namespace
}  // namespace posed
