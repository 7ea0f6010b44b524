// IMU preintegration against an analytic motion: the deltas predict the true end state, the
// residual vanishes at the truth, the bias Jacobians match finite differences, and the
// covariance matches the spread of noisy integrations.

#include "core/imu/preintegration.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tests/unit/estimator/analytic_motion.hpp"

namespace posed::imu {
namespace {

constexpr double kRateHz = 200.0;

Preintegration integrate(const test::AnalyticMotion& m, double t0, double t1, const ImuBias& lin,
                         const ImuBias& true_bias = {}, const ImuNoise& noise = {},
                         std::mt19937* rng = nullptr, double noise_scale = 0.0) {
  Preintegration pre(noise, lin, HostTime::from_ns(0));
  std::normal_distribution<double> n01(0, 1);
  const int steps = static_cast<int>(std::lround((t1 - t0) * kRateHz));
  for (int k = 0; k <= steps; ++k) {
    ImuSample s = m.sample(t0 + k / kRateHz);
    s.angular_velocity_radps += true_bias.gyro_radps;
    s.specific_force_mps2 += true_bias.accel_mps2;
    if (rng != nullptr) {
      const double sg = noise.gyro_noise_density * std::sqrt(kRateHz) * noise_scale;
      const double sa = noise.accel_noise_density * std::sqrt(kRateHz) * noise_scale;
      for (int i = 0; i < 3; ++i) {
        s.angular_velocity_radps[i] += sg * n01(*rng);
        s.specific_force_mps2[i] += sa * n01(*rng);
      }
    }
    pre.add(s);
  }
  return pre;
}

TEST(Preintegration, PredictsTheTrueEndStateOfAnAnalyticMotion) {
  const test::AnalyticMotion m;
  const Preintegration pre = integrate(m, 1.0, 3.0, {});
  EXPECT_NEAR(pre.dt_s(), 2.0, 1e-9);
  const ImuState predicted = pre.predict(m.state(1.0), m.gravity_mps2);
  const ImuState truth = m.state(3.0);
  // Midpoint integration at 200 Hz over 2 s of 0.6 rad/s turning and ~1 m/s² accelerations.
  EXPECT_LT((predicted.p_map_imu_m - truth.p_map_imu_m).norm(), 2e-4);
  EXPECT_LT((predicted.v_map_mps - truth.v_map_mps).norm(), 2e-4);
  EXPECT_LT(predicted.q_map_imu.angularDistance(truth.q_map_imu), 2e-5);
  EXPECT_LT(pre.residual(m.state(1.0), truth, m.gravity_mps2).norm(), 3e-4);
  // A wrong end state is seen: 10 cm off in x shows in the position residual.
  ImuState off = truth;
  off.p_map_imu_m.x() += 0.1;
  EXPECT_NEAR(pre.residual(m.state(1.0), off, m.gravity_mps2).segment<3>(6).norm(), 0.1, 1e-3);
}

TEST(Preintegration, BiasJacobiansMatchFiniteDifferences) {
  const test::AnalyticMotion m;
  const ImuBias lin{};
  const Preintegration base = integrate(m, 0.0, 1.0, lin);
  for (int axis = 0; axis < 6; ++axis) {
    ImuBias d;
    const double h = 1e-4;
    if (axis < 3) {
      d.gyro_radps[axis] = h;
    } else {
      d.accel_mps2[axis - 3] = h;
    }
    // Re-integrating with the other bias as linearisation point is the truth for the correction.
    const Preintegration moved = integrate(m, 0.0, 1.0, d);
    const Eigen::Matrix3d dR = base.corrected_delta_R(d.gyro_radps);
    EXPECT_LT(so3::log(Eigen::Matrix3d(dR.transpose() * moved.delta_R())).norm(), 1e-8) << axis;
    EXPECT_LT((base.corrected_delta_v(d.gyro_radps, d.accel_mps2) - moved.delta_v()).norm(), 1e-7)
        << axis;
    EXPECT_LT((base.corrected_delta_p(d.gyro_radps, d.accel_mps2) - moved.delta_p()).norm(), 1e-7)
        << axis;
  }
}

TEST(Preintegration, ABiasIsCorrectedWithoutReintegrating) {
  const test::AnalyticMotion m;
  ImuBias true_bias;
  true_bias.gyro_radps = {0.01, -0.02, 0.015};
  true_bias.accel_mps2 = {0.1, 0.05, -0.08};
  // Integrated with zero bias, evaluated with the true bias: the first-order correction.
  const Preintegration pre = integrate(m, 2.0, 2.5, ImuBias{}, true_bias);
  ImuState start = m.state(2.0);
  start.bias = true_bias;
  ImuState end = m.state(2.5);
  end.bias = true_bias;
  // What remains is second order in the bias (0.02 rad/s over 0.5 s tilts by 0.01 rad; its square
  // times ~10 m/s² over 0.5 s is ~3e-4).
  const double corrected = pre.residual(start, end, m.gravity_mps2).norm();
  EXPECT_LT(corrected, 1e-3);
  // Without the correction the residual is over ten times larger.
  start.bias = {};
  EXPECT_GT(pre.residual(start, end, m.gravity_mps2).norm(), 10 * corrected);
}

TEST(Preintegration, CovarianceMatchesTheSpreadOfNoisyIntegrations) {
  const test::AnalyticMotion m;
  ImuNoise noise;
  noise.gyro_noise_density = 2e-3;
  noise.accel_noise_density = 3e-2;
  std::mt19937 rng(7);
  // Mahalanobis distance of the residual at the truth: chi-squared with 9 degrees of freedom.
  double sum_chi2 = 0;
  constexpr int kRuns = 200;
  Eigen::Matrix<double, 9, 9> info;
  for (int run = 0; run < kRuns; ++run) {
    const Preintegration pre = integrate(m, 0.0, 0.5, {}, {}, noise, &rng, 1.0);
    if (run == 0) info = pre.covariance().inverse();
    const auto r = pre.residual(m.state(0.0), m.state(0.5), m.gravity_mps2);
    sum_chi2 += r.dot(info * r);
  }
  const double mean_chi2 = sum_chi2 / kRuns;
  // E[chi2(9)] = 9; 200 runs put the mean within ~0.6 of it (1 sigma = sqrt(18/200) = 0.3).
  EXPECT_NEAR(mean_chi2, 9.0, 1.5);
}

TEST(Preintegration, IntervalsEndExactlyAtAStampBetweenSamples) {
  const test::AnalyticMotion m;
  Preintegration pre(ImuNoise{}, ImuBias{}, HostTime::from_ns(0));
  pre.add(m.sample(0.0));
  pre.add(m.sample(0.005));
  pre.add_until(HostTime::from_ns(7'000'000), m.sample(0.010));
  EXPECT_EQ(pre.end(), HostTime::from_ns(7'000'000));
  EXPECT_NEAR(pre.dt_s(), 0.007, 1e-12);
  const ImuState predicted = pre.predict(m.state(0.0), m.gravity_mps2);
  EXPECT_LT((predicted.p_map_imu_m - m.p(0.007)).norm(), 1e-6);
}

TEST(Preintegration, TheBackupImusSamplesAreWeighedWithItsOwnNoise) {
  const test::AnalyticMotion m;
  const ImuNoise a9{2.3e-3, 3.8e-2, 1.4e-5, 1.1e-3};
  const ImuNoise d435i{2.4e-4, 1.5e-3, 1.0e-5, 5.0e-4, 3e-3, 5e-2};
  // The same samples: the A9's alone, the D435i's alone, and the D435i's over the second half.
  Preintegration primary(a9, d435i, ImuBias{}, HostTime::from_ns(0));
  Preintegration backup(a9, d435i, ImuBias{}, HostTime::from_ns(0));
  Preintegration mixed(a9, d435i, ImuBias{}, HostTime::from_ns(0));
  Preintegration only_d435i(d435i, ImuBias{}, HostTime::from_ns(0));
  for (int k = 0; k <= 100; ++k) {
    ImuSample s = m.sample(k / kRateHz);
    primary.add(s);
    s.from_backup_imu = true;
    backup.add(s);
    only_d435i.add(s);
    s.from_backup_imu = k > 50;
    mixed.add(s);
  }
  // The deltas do not depend on whose samples they are; the weights do.
  EXPECT_EQ(primary.delta_p(), backup.delta_p());
  EXPECT_EQ(backup.covariance(), only_d435i.covariance());
  EXPECT_DOUBLE_EQ(backup.backup_dt_s(), 0.5);
  EXPECT_DOUBLE_EQ(mixed.backup_dt_s(), 0.25);
  EXPECT_DOUBLE_EQ(primary.backup_dt_s(), 0.0);
  // Position variance: the A9's accelerometer is 25x noisier; half the interval on the D435i
  // lies in between.
  const double p_primary = primary.covariance()(6, 6), p_backup = backup.covariance()(6, 6),
               p_mixed = mixed.covariance()(6, 6);
  EXPECT_GT(p_primary, 100 * p_backup);
  EXPECT_LT(p_mixed, p_primary);
  EXPECT_GT(p_mixed, p_backup);
  // Bias random walk: each IMU's density over the time it measured.
  EXPECT_DOUBLE_EQ(primary.accel_bias_walk_variance(), 1.1e-3 * 1.1e-3 * 0.5);
  EXPECT_DOUBLE_EQ(backup.accel_bias_walk_variance(), 5.0e-4 * 5.0e-4 * 0.5);
  // and the step between the two IMUs' biases where one follows the other.
  EXPECT_EQ(mixed.imu_switches(), 1);
  EXPECT_EQ(backup.imu_switches(), 0);
  EXPECT_NEAR(mixed.gyro_bias_walk_variance(),
              1.4e-5 * 1.4e-5 * 0.25 + 1.0e-5 * 1.0e-5 * 0.25 + 3e-3 * 3e-3, 1e-18);
  EXPECT_NEAR(mixed.accel_bias_walk_variance(),
              1.1e-3 * 1.1e-3 * 0.25 + 5.0e-4 * 5.0e-4 * 0.25 + 5e-2 * 5e-2, 1e-15);
  // An interval cut short at a stamp between samples belongs to the sample it ends on.
  Preintegration cut(a9, d435i, ImuBias{}, HostTime::from_ns(0));
  ImuSample first = m.sample(0.0), next = m.sample(0.005);
  next.from_backup_imu = true;
  cut.add(first);
  cut.add_until(HostTime::from_ns(3'000'000), next);
  EXPECT_DOUBLE_EQ(cut.backup_dt_s(), 0.003);
}

}  // namespace
}  // namespace posed::imu
