// The analytic Jacobians of the window's factors against Ceres's numeric differentiation, at
// states away from the measurements (so every term of the residuals is non-zero).

#include "core/estimator/factors.hpp"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/estimator/pose_manifold.hpp"
#include "tests/unit/estimator/analytic_motion.hpp"

namespace posed::estimator {
namespace {

void state_arrays(const imu::ImuState& s, double* pose, double* sb) {
  for (int i = 0; i < 3; ++i) {
    pose[i] = s.p_map_imu_m[i];
    sb[i] = s.v_map_mps[i];
    sb[3 + i] = s.bias.gyro_radps[i];
    sb[6 + i] = s.bias.accel_mps2[i];
  }
  const Eigen::Quaterniond q = s.q_map_imu.normalized();
  pose[3] = q.x();
  pose[4] = q.y();
  pose[5] = q.z();
  pose[6] = q.w();
}

/// A state at the pose T_map_imu, at rest with zero biases.
imu::ImuState state_at_pose(const Eigen::Isometry3d& T_map_imu) {
  imu::ImuState s;
  s.q_map_imu = Eigen::Quaterniond(T_map_imu.linear());
  s.p_map_imu_m = T_map_imu.translation();
  return s;
}

/// Every Jacobian entry (in the tangent spaces) agrees with numeric differentiation to `tol`
/// relative to its size (absolute below 1): GradientChecker's own verdict flags two zeros that
/// differ by rounding.
void expect_jacobians_match(const ceres::GradientChecker::ProbeResults& r, double tol) {
  ASSERT_EQ(r.local_jacobians.size(), r.local_numeric_jacobians.size());
  for (std::size_t b = 0; b < r.local_jacobians.size(); ++b) {
    const Eigen::MatrixXd& a = r.local_jacobians[b];
    const Eigen::MatrixXd& n = r.local_numeric_jacobians[b];
    for (Eigen::Index i = 0; i < a.rows(); ++i) {
      for (Eigen::Index k = 0; k < a.cols(); ++k) {
        EXPECT_NEAR(a(i, k), n(i, k), tol * std::max(1.0, std::abs(n(i, k))))
            << "block " << b << " row " << i << " col " << k;
      }
    }
  }
}

/// Probes `factor` at `params` with ceres' GradientChecker (the pose blocks, where `is_pose`
/// says, on PoseManifold; `relative_step` its numeric step) and expects analytic and numeric
/// Jacobians to match to `tol`.
void expect_jacobians_match(const ceres::CostFunction& factor, double const* const* params,
                            const std::vector<bool>& is_pose, double relative_step, double tol) {
  PoseManifold pose_manifold;
  std::vector<const ceres::Manifold*> manifolds;
  for (const bool pose : is_pose) manifolds.push_back(pose ? &pose_manifold : nullptr);
  ceres::NumericDiffOptions options;
  ceres::GradientChecker checker(&factor, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(params, relative_step, &results);
  expect_jacobians_match(results, tol);
}

/// A state turning, tilted and moving, with biases: where the factors' Jacobians are checked.
imu::ImuState moving_state() {
  imu::ImuState s;
  s.q_map_imu = Eigen::Quaterniond(so3::exp(Eigen::Vector3d(0.12, -0.18, 0.45)));
  s.p_map_imu_m = Eigen::Vector3d(3.1, -2.2, 0.4);
  s.v_map_mps = Eigen::Vector3d(1.1, 0.7, 0.05);
  s.bias.gyro_radps = {0.01, -0.02, 0.005};
  s.bias.accel_mps2 = {0.05, 0.02, -0.04};
  return s;
}

/// The motion's IMU samples from 1.0 to 1.2 s, preintegrated about biases away from zero.
imu::Preintegration preintegrated_from_1_to_1_2_s(const test::AnalyticMotion& m) {
  imu::ImuBias lin;
  lin.gyro_radps = {0.01, -0.02, 0.005};
  lin.accel_mps2 = {0.05, 0.02, -0.04};
  imu::Preintegration pre({2e-3, 3e-2, 1e-5, 1e-3}, lin, HostTime::from_ns(0));
  for (int k = 0; k <= 40; ++k) pre.add(m.sample(1.0 + k / 200.0));
  return pre;
}

TEST(Factors, ImuFactorJacobiansMatchNumericDifferentiation) {
  const test::AnalyticMotion m;
  const imu::Preintegration pre = preintegrated_from_1_to_1_2_s(m);
  const ImuFactor factor(pre, m.gravity_mps2);

  imu::ImuState i = m.state(1.0), j = m.state(1.2);
  i.p_map_imu_m += Eigen::Vector3d(0.1, -0.05, 0.02);
  i.q_map_imu = i.q_map_imu * so3::exp_q(Eigen::Vector3d(0.02, -0.01, 0.03));
  j.v_map_mps += Eigen::Vector3d(0.05, 0.1, -0.02);
  i.bias.gyro_radps = {0.012, -0.018, 0.004};
  i.bias.accel_mps2 = {0.06, 0.01, -0.03};
  j.bias = i.bias;
  j.bias.accel_mps2.x() += 0.01;
  double pose_i[7], sb_i[9], pose_j[7], sb_j[9];
  state_arrays(i, pose_i, sb_i);
  state_arrays(j, pose_j, sb_j);
  const double* params[] = {pose_i, sb_i, pose_j, sb_j};

  expect_jacobians_match(factor, params, {true, false, true, false}, 1e-5, 1e-5);
}

TEST(Factors, ImuFactorWithTheMapsTiltJacobiansMatchNumericDifferentiation) {
  // The same factor with gravity's direction in the map as a fifth block, at a tilt of about a
  // degree (what a moving start-up alignment leaves).
  const test::AnalyticMotion m;
  const imu::Preintegration pre = preintegrated_from_1_to_1_2_s(m);
  const ImuFactor factor(pre, m.gravity_mps2, true);
  ASSERT_EQ(factor.parameter_block_sizes().size(), 5u);

  imu::ImuState i = m.state(1.0), j = m.state(1.2);
  i.p_map_imu_m += Eigen::Vector3d(0.1, -0.05, 0.02);
  j.v_map_mps += Eigen::Vector3d(0.05, 0.1, -0.02);
  i.bias.accel_mps2 = {0.06, 0.01, -0.03};
  j.bias = i.bias;
  double pose_i[7], sb_i[9], pose_j[7], sb_j[9];
  state_arrays(i, pose_i, sb_i);
  state_arrays(j, pose_j, sb_j);
  double tilt[2] = {0.012, -0.02};
  const double* params[] = {pose_i, sb_i, pose_j, sb_j, tilt};
  expect_jacobians_match(factor, params, {true, false, true, false, false}, 1e-5, 1e-5);

  // At zero tilt it is the plain factor.
  const ImuFactor plain(pre, m.gravity_mps2);
  double zero[2] = {0, 0};
  const double* tilted_params[] = {pose_i, sb_i, pose_j, sb_j, zero};
  Eigen::Matrix<double, 15, 1> r_tilted, r_plain;
  ASSERT_TRUE(factor.Evaluate(tilted_params, r_tilted.data(), nullptr));
  ASSERT_TRUE(plain.Evaluate(params, r_plain.data(), nullptr));
  EXPECT_LT((r_tilted - r_plain).norm(), 1e-9 * std::max(1.0, r_plain.norm()));
  // And the tilt turns gravity: 0.02 rad about y moves it by g sin(0.02) along -x.
  const Eigen::Vector3d g = tilted_gravity(9.8, tilt);
  EXPECT_NEAR(g.norm(), 9.8, 1e-9);
  EXPECT_NEAR(g.x(), -9.8 * std::sin(-0.02) * std::cos(0.012), 2e-3);
}

TEST(Factors, LidarPoseFactorJacobiansMatchNumericDifferentiation) {
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();
  T_imu_lidar.linear() = so3::exp(Eigen::Vector3d(0.01, 0.02, -0.5));
  T_imu_lidar.translation() = Eigen::Vector3d(0.27, -0.01, 0.18);
  Eigen::Isometry3d T_meas = Eigen::Isometry3d::Identity();
  T_meas.linear() = so3::exp(Eigen::Vector3d(0.1, -0.2, 1.0));
  T_meas.translation() = Eigen::Vector3d(3, -2, 0.5);
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Identity() * 100;
  info(0, 4) = info(4, 0) = 20;  // correlated, as a scan's information is
  const LidarPoseFactor factor(T_meas, T_imu_lidar, info);
  imu::ImuState s;
  s.q_map_imu = Eigen::Quaterniond(so3::exp(Eigen::Vector3d(0.12, -0.18, 0.45)));
  s.p_map_imu_m = Eigen::Vector3d(3.1, -2.2, 0.4);
  double pose[7], sb[9];
  state_arrays(s, pose, sb);
  const double* params[] = {pose};
  expect_jacobians_match(factor, params, {true}, 1e-6, 1e-6);
}

TEST(Factors, RelativePoseFactorJacobiansMatchNumericDifferentiation) {
  Eigen::Isometry3d T_meas = Eigen::Isometry3d::Identity();
  T_meas.linear() = so3::exp(Eigen::Vector3d(0.02, -0.03, 0.1));
  T_meas.translation() = Eigen::Vector3d(0.12, -0.02, 0.01);
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Identity() * 400;
  info(1, 3) = info(3, 1) = 50;  // a camera's rotation and translation are correlated
  const RelativePoseFactor factor(T_meas, info);
  imu::ImuState i, j;
  i.q_map_imu = Eigen::Quaterniond(so3::exp(Eigen::Vector3d(0.12, -0.18, 0.45)));
  i.p_map_imu_m = Eigen::Vector3d(3.1, -2.2, 0.4);
  j.q_map_imu = Eigen::Quaterniond(so3::exp(Eigen::Vector3d(0.1, -0.15, 0.6)));
  j.p_map_imu_m = Eigen::Vector3d(3.3, -2.1, 0.45);
  double pose_i[7], pose_j[7], sb[9];
  state_arrays(i, pose_i, sb);
  state_arrays(j, pose_j, sb);
  const double* params[] = {pose_i, pose_j};
  expect_jacobians_match(factor, params, {true, true}, 1e-6, 1e-6);
}

TEST(Factors, VehicleMotionFactorJacobiansMatchNumericDifferentiation) {
  // Turning and driving with a sideways and vertical slip, about a no-slip point behind the IMU.
  const VehicleMotionFactor factor(Eigen::Vector3d(0.05, -0.02, 0.4),
                                   Eigen::Vector3d(-0.3, 0.05, -0.2), 0.05, 0.08);
  const imu::ImuState s = moving_state();
  double pose[7], sb[9];
  state_arrays(s, pose, sb);
  const double* params[] = {pose, sb};
  expect_jacobians_match(factor, params, {true, false}, 1e-6, 1e-6);
}

TEST(Factors, VehicleMotionFactorIsZeroForAVehicleDrivingAlongItsXAndLargeForSideways) {
  // Yawed by 0.6 rad and driving along its x at 2 m/s, turning at 0.5 rad/s about its own point.
  imu::ImuState s;
  s.q_map_imu = Eigen::Quaterniond(so3::exp(Eigen::Vector3d(0, 0, 0.6)));
  s.v_map_mps = s.q_map_imu * Eigen::Vector3d(2.0, 0, 0);
  double pose[7], sb[9];
  state_arrays(s, pose, sb);
  const double* params[] = {pose, sb};
  double r[2];
  const VehicleMotionFactor at_imu(Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d::Zero(), 0.05, 0.05);
  ASSERT_TRUE(at_imu.Evaluate(params, r, nullptr));
  EXPECT_NEAR(r[0], 0.0, 1e-12);
  EXPECT_NEAR(r[1], 0.0, 1e-12);
  // The same motion judged about a no-slip point 0.4 m behind the IMU: the IMU then swings
  // sideways at 0.5 * 0.4 = 0.2 m/s, which that point does not: 4 sigma.
  const VehicleMotionFactor behind(Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d(-0.4, 0, 0), 0.05,
                                   0.05);
  ASSERT_TRUE(behind.Evaluate(params, r, nullptr));
  EXPECT_NEAR(r[0], -4.0, 1e-9);
  // Driving sideways at 0.1 m/s: 2 sigma.
  s.v_map_mps = s.q_map_imu * Eigen::Vector3d(2.0, 0.1, 0);
  state_arrays(s, pose, sb);
  ASSERT_TRUE(at_imu.Evaluate(params, r, nullptr));
  EXPECT_NEAR(r[0], 2.0, 1e-9);
}

TEST(Factors, LandmarkFactorJacobiansMatchNumericDifferentiation) {
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
  T_body_cam.linear() = so3::exp(Eigen::Vector3d(-1.5, 0.05, -1.55));  // looking ahead, z forward
  T_body_cam.translation() = Eigen::Vector3d(0.1, 0.02, 0.05);
  const LandmarkFactor factor(Eigen::Vector3d(4.0, 0.6, 0.3), T_body_cam,
                              Eigen::Vector2d(0.03, -0.02), 600.0);
  imu::ImuState a, j;
  a.q_map_imu = Eigen::Quaterniond(so3::exp(Eigen::Vector3d(0.02, -0.01, 0.45)));
  a.p_map_imu_m = Eigen::Vector3d(3.1, -2.2, 0.4);
  j.q_map_imu = Eigen::Quaterniond(so3::exp(Eigen::Vector3d(0.01, 0.02, 0.5)));
  j.p_map_imu_m = Eigen::Vector3d(3.6, -1.9, 0.42);
  double pose_a[7], pose_j[7], sb[9];
  state_arrays(a, pose_a, sb);
  state_arrays(j, pose_j, sb);
  double r[2];
  const double* params[] = {pose_a, pose_j};
  ASSERT_TRUE(factor.Evaluate(params, r, nullptr));
  EXPECT_GT(std::hypot(r[0], r[1]), 1.0);  // away from the measurement: every term counts
  expect_jacobians_match(factor, params, {true, true}, 1e-6, 1e-5);
}

TEST(Factors, LandmarkFactorIsZeroWhereThePointProjectsOntoItsObservation) {
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
  T_body_cam.linear() = so3::exp(Eigen::Vector3d(-1.5, 0.05, -1.55));
  T_body_cam.translation() = Eigen::Vector3d(0.1, 0.02, 0.05);
  Eigen::Isometry3d T_map_a = Eigen::Isometry3d::Identity(), T_map_j = T_map_a;
  T_map_a.linear() = so3::exp(Eigen::Vector3d(0.0, 0.0, 0.3));
  T_map_j.linear() = so3::exp(Eigen::Vector3d(0.0, 0.01, 0.35));
  T_map_j.translation() = Eigen::Vector3d(0.4, 0.1, 0.0);
  const Eigen::Vector3d X_a(5.0, -0.4, 0.7);
  const Eigen::Vector3d P_c = (T_map_j * T_body_cam).inverse() * (T_map_a * X_a);
  const LandmarkFactor factor(X_a, T_body_cam, P_c.head<2>() / P_c.z(), 600.0);
  EXPECT_LT((factor.point_in_camera(T_map_a, T_map_j) - P_c).norm(), 1e-12);
  const imu::ImuState a = state_at_pose(T_map_a), j = state_at_pose(T_map_j);
  double pose_a[7], pose_j[7], sb[9], r[2];
  state_arrays(a, pose_a, sb);
  state_arrays(j, pose_j, sb);
  const double* params[] = {pose_a, pose_j};
  ASSERT_TRUE(factor.Evaluate(params, r, nullptr));
  EXPECT_NEAR(r[0], 0.0, 1e-9);
  EXPECT_NEAR(r[1], 0.0, 1e-9);
  // One metre further along the camera's view the point projects elsewhere.
  pose_j[2] += 1.0;
  ASSERT_TRUE(factor.Evaluate(params, r, nullptr));
  EXPECT_GT(std::hypot(r[0], r[1]), 1.0);
}

TEST(Factors, RelativePoseFactorIsZeroAtTheMeasuredMotion) {
  Eigen::Isometry3d T_i = Eigen::Isometry3d::Identity(), T_ij = Eigen::Isometry3d::Identity();
  T_i.linear() = so3::exp(Eigen::Vector3d(0.3, -0.1, 1.2));
  T_i.translation() = Eigen::Vector3d(5, 1, -2);
  T_ij.linear() = so3::exp(Eigen::Vector3d(0.01, 0.02, 0.05));
  T_ij.translation() = Eigen::Vector3d(0.1, 0.01, 0.0);
  const Eigen::Isometry3d T_j = T_i * T_ij;
  const RelativePoseFactor factor(T_ij, Eigen::Matrix<double, 6, 6>::Identity() * 1e4);
  const imu::ImuState i = state_at_pose(T_i);
  imu::ImuState j = state_at_pose(T_j);
  double pose_i[7], pose_j[7], sb[9], r[6];
  state_arrays(i, pose_i, sb);
  state_arrays(j, pose_j, sb);
  const double* params[] = {pose_i, pose_j};
  ASSERT_TRUE(factor.Evaluate(params, r, nullptr));
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  EXPECT_LT(Eigen::Map<Vec6>(r).norm(), 1e-9);
  // 1 cm off along x in frame i: a residual of 1 cm times the square-root information.
  j.p_map_imu_m += T_i.linear() * Eigen::Vector3d(0.01, 0, 0);
  state_arrays(j, pose_j, sb);
  ASSERT_TRUE(factor.Evaluate(params, r, nullptr));
  EXPECT_NEAR(Eigen::Map<Vec6>(r).norm(), 0.01 * 100, 1e-3);
}

}  // namespace
}  // namespace posed::estimator
