// Marginalisation with camera factors in the window: a fixed-lag window that drops its oldest
// states into a prior must end where a batch solve over every state ends (exactly, for a
// linear-Gaussian problem; here to a tenth of the noise, as the factors are mildly nonlinear).
// Noisy IMU, noisy relative-motion ("between") factors and a single absolute pose at the start:
// the newest state's position is carried only through the factors and the priors marginalisation
// leaves, so a prior that lost the between factors' information would show.

#include <gtest/gtest.h>

#include <random>

#include "core/estimator/factors.hpp"
#include "core/estimator/sliding_window.hpp"
#include "tests/unit/estimator/analytic_motion.hpp"

namespace posed::estimator {
namespace {

constexpr double kMargImuHz = 200.0;
constexpr double kMargStep = 0.1;

/// The IMU's samples over the step ending at `t`, with white noise at `noise_density`,
/// preintegrated from `prev`.
imu::Preintegration noisy_preintegration(const test::AnalyticMotion& m,
                                         const imu::ImuNoise& noise_density,
                                         const imu::ImuState& prev, double t, std::mt19937& rng,
                                         std::normal_distribution<double>& n01) {
  imu::Preintegration pre(noise_density, prev.bias, prev.stamp);
  for (int i = 0; i <= static_cast<int>(std::lround(kMargStep * kMargImuHz)); ++i) {
    ImuSample s = m.sample(t - kMargStep + i / kMargImuHz);
    for (int a = 0; a < 3; ++a) {
      s.angular_velocity_radps[a] +=
          noise_density.gyro_noise_density * std::sqrt(kMargImuHz) * n01(rng);
      s.specific_force_mps2[a] +=
          noise_density.accel_noise_density * std::sqrt(kMargImuHz) * n01(rng);
    }
    pre.add(s);
  }
  return pre;
}

/// The last state of a window of `size` run over `states` steps of the same noisy data.
imu::ImuState run_window(int size, int steps) {
  const test::AnalyticMotion m;
  const imu::ImuNoise noise_density = {2e-3, 2e-2, 1e-5, 1e-3};
  SlidingWindowConfig c;
  c.size = size;
  c.max_iterations = 30;
  c.gravity_mps2 = m.gravity_mps2;
  SlidingWindow w(c);
  std::mt19937 rng(11);
  std::normal_distribution<double> n01(0, 1);
  Eigen::Matrix<double, 15, 1> sigma;
  sigma << Eigen::Vector3d::Constant(1e-3), Eigen::Vector3d::Constant(1e-3),
      Eigen::Vector3d::Constant(0.05), Eigen::Vector3d::Constant(1e-3),
      Eigen::Vector3d::Constant(0.02);
  w.reset(m.state(0.0), sigma);
  const double sigma_p = 0.01, sigma_r = 0.002;
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Zero();
  info.topLeftCorner<3, 3>().diagonal().setConstant(1.0 / (sigma_r * sigma_r));
  info.bottomRightCorner<3, 3>().diagonal().setConstant(1.0 / (sigma_p * sigma_p));
  for (int k = 1; k <= steps; ++k) {
    const double t = k * kMargStep;
    const imu::ImuState prev = w.latest();
    const imu::Preintegration pre = noisy_preintegration(m, noise_density, prev, t, rng, n01);
    imu::ImuState guess = pre.predict(prev, m.gravity_mps2);
    guess.stamp = m.state(t).stamp;
    // The camera's motion since the previous state, with noise.
    Eigen::Isometry3d T_ij =
        imu::T_map_imu(m.state(t - kMargStep)).inverse() * imu::T_map_imu(m.state(t));
    T_ij.translation() += sigma_p * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    T_ij.linear() =
        T_ij.linear() * so3::exp(sigma_r * Eigen::Vector3d(n01(rng), n01(rng), n01(rng)));
    const std::uint64_t previous = w.latest_id();
    w.add(guess, pre, std::nullopt);
    EXPECT_TRUE(w.add_factor(FactorKind::kVisible, std::make_unique<RelativePoseFactor>(T_ij, info),
                             {{previous, BlockRole::kPose}, {w.latest_id(), BlockRole::kPose}}));
    EXPECT_TRUE(w.solve());
  }
  return w.latest();
}

TEST(Marginalisation, AFixedLagWindowWithCameraFactorsEndsWhereTheBatchSolveEnds) {
  const int steps = 30;
  const imu::ImuState batch = run_window(steps + 1, steps);  // nothing marginalised
  const imu::ImuState windowed = run_window(4, steps);       // 26 states marginalised
  const imu::ImuState truth = test::AnalyticMotion().state(steps * kMargStep);
  const double batch_error = (batch.p_map_imu_m - truth.p_map_imu_m).norm();
  const double difference = (windowed.p_map_imu_m - batch.p_map_imu_m).norm();
  std::printf("batch error %.4f m, windowed - batch %.5f m\n", batch_error, difference);
  EXPECT_GT(batch_error, 0.005);  // the noise shows: the comparison below is not trivial
  EXPECT_LT(difference, 0.1 * batch_error);
  EXPECT_LT((windowed.v_map_mps - batch.v_map_mps).norm(), 0.01);
  EXPECT_LT(windowed.q_map_imu.angularDistance(batch.q_map_imu), 1e-3);
}

/// The same with landmark reprojection factors instead of between factors: every state sees 8
/// new points (their anchor, where their depth is known to 2 %) and observes each again from the
/// next 3 states with 1 px of noise, so a landmark's factors all lie within a window of 4 and both
/// runs solve the same problem.
imu::ImuState run_landmark_window(int size, int steps) {
  const test::AnalyticMotion m;
  const imu::ImuNoise noise_density = {2e-3, 2e-2, 1e-5, 1e-3};
  SlidingWindowConfig c;
  c.size = size;
  c.max_iterations = 30;
  c.gravity_mps2 = m.gravity_mps2;
  SlidingWindow w(c);
  std::mt19937 rng(13);
  std::normal_distribution<double> n01(0, 1);
  std::uniform_real_distribution<double> ahead(3, 8), side(-2, 2), up(-1, 1);
  Eigen::Matrix<double, 15, 1> sigma;
  sigma << Eigen::Vector3d::Constant(1e-3), Eigen::Vector3d::Constant(1e-3),
      Eigen::Vector3d::Constant(0.05), Eigen::Vector3d::Constant(1e-3),
      Eigen::Vector3d::Constant(0.02);
  w.reset(m.state(0.0), sigma);
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
  T_body_cam.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // camera z along body x
  T_body_cam.translation() = Eigen::Vector3d(0.2, 0.0, 0.3);
  constexpr double kFocalPx = 600;
  struct Point {
    std::uint64_t anchor_id;
    int anchor_step;
    Eigen::Vector3d X_anchor_true, X_anchor_measured;
  };
  std::vector<Point> points;
  for (int k = 1; k <= steps; ++k) {
    const double t = k * kMargStep;
    const imu::ImuState prev = w.latest();
    const imu::Preintegration pre = noisy_preintegration(m, noise_density, prev, t, rng, n01);
    imu::ImuState guess = pre.predict(prev, m.gravity_mps2);
    guess.stamp = m.state(t).stamp;
    w.add(guess, pre, std::nullopt);
    const Eigen::Isometry3d T_map_j = imu::T_map_imu(m.state(t));
    for (const Point& p : points) {
      if (k - p.anchor_step > 3) continue;
      const Eigen::Vector3d P_c =
          (T_map_j * T_body_cam).inverse() *
          (imu::T_map_imu(m.state(p.anchor_step * kMargStep)) * p.X_anchor_true);
      const Eigen::Vector2d observed =
          P_c.hnormalized() + Eigen::Vector2d(n01(rng), n01(rng)) / kFocalPx;
      EXPECT_TRUE(w.add_factor(
          FactorKind::kVisible,
          std::make_unique<LandmarkFactor>(p.X_anchor_measured, T_body_cam, observed, kFocalPx),
          {{p.anchor_id, BlockRole::kPose}, {w.latest_id(), BlockRole::kPose}}));
    }
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d X(ahead(rng), side(rng), up(rng));
      points.push_back({w.latest_id(), k, X, X * (1.0 + 0.02 * n01(rng))});
    }
    EXPECT_TRUE(w.solve());
  }
  return w.latest();
}

TEST(Marginalisation, AFixedLagWindowWithLandmarkFactorsEndsWhereTheBatchSolveEnds) {
  const int steps = 30;
  const imu::ImuState batch = run_landmark_window(steps + 1, steps);
  const imu::ImuState windowed = run_landmark_window(4, steps);
  const imu::ImuState truth = test::AnalyticMotion().state(steps * kMargStep);
  const double batch_error = (batch.p_map_imu_m - truth.p_map_imu_m).norm();
  const double difference = (windowed.p_map_imu_m - batch.p_map_imu_m).norm();
  std::printf("landmarks: batch error %.4f m, windowed - batch %.5f m\n", batch_error, difference);
  EXPECT_GT(batch_error, 0.005);
  EXPECT_LT(difference, 0.1 * batch_error);
  EXPECT_LT((windowed.v_map_mps - batch.v_map_mps).norm(), 0.01);
  EXPECT_LT(windowed.q_map_imu.angularDistance(batch.q_map_imu), 1e-3);
}

}  // namespace
}  // namespace posed::estimator
