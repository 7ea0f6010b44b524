// The fixed-lag window on an analytic motion with perfect lidar poses: it must recover the
// trajectory and a known IMU bias, and keep doing so as states are marginalised.

#include "core/estimator/sliding_window.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tests/unit/estimator/analytic_motion.hpp"

namespace posed::estimator {
namespace {

constexpr double kImuHz = 200.0;

struct Result {
  double max_position_error_m = 0;
  double max_rotation_error_rad = 0;
  imu::ImuBias final_bias;
};

Result run(const imu::ImuBias& true_bias, double duration_s, int window, double lidar_sigma_m,
           bool noise) {
  const test::AnalyticMotion m;
  const imu::ImuNoise noise_density = {2.3e-3, 3.8e-2, 1.4e-5, 1.1e-3};
  SlidingWindowConfig c;
  c.size = window;
  c.gravity_mps2 = m.gravity_mps2;
  c.T_imu_lidar.translation() = Eigen::Vector3d(0.27, 0.0, 0.18);
  SlidingWindow w(c);
  std::mt19937 rng(5);
  std::normal_distribution<double> n01(0, 1);

  imu::ImuState start = m.state(0.0);  // zero bias guess
  Eigen::Matrix<double, 15, 1> sigma;
  sigma << Eigen::Vector3d::Constant(1e-3), Eigen::Vector3d::Constant(1e-3),
      Eigen::Vector3d::Constant(0.1), Eigen::Vector3d::Constant(0.01),
      Eigen::Vector3d::Constant(0.3);
  w.reset(start, sigma);
  Result r;
  const double dt_scan = 0.1;
  for (double t = dt_scan; t <= duration_s + 1e-9; t += dt_scan) {
    const imu::ImuState prev = w.latest();
    imu::Preintegration pre(noise_density, prev.bias, prev.stamp);
    const int steps = static_cast<int>(std::lround(dt_scan * kImuHz));
    for (int k = 0; k <= steps; ++k) {
      ImuSample s = m.sample(t - dt_scan + k / kImuHz);
      s.angular_velocity_radps += true_bias.gyro_radps;
      s.specific_force_mps2 += true_bias.accel_mps2;
      if (noise) {
        for (int a = 0; a < 3; ++a) {
          s.angular_velocity_radps[a] +=
              noise_density.gyro_noise_density * std::sqrt(kImuHz) * n01(rng);
          s.specific_force_mps2[a] +=
              noise_density.accel_noise_density * std::sqrt(kImuHz) * n01(rng);
        }
      }
      pre.add(s);
    }
    imu::ImuState guess = pre.predict(prev, m.gravity_mps2);
    const imu::ImuState truth = m.state(t);
    Eigen::Isometry3d T_map_imu = Eigen::Isometry3d::Identity();
    T_map_imu.linear() = truth.q_map_imu.toRotationMatrix();
    T_map_imu.translation() = truth.p_map_imu_m;
    LidarPose lidar;
    lidar.T_map_lidar = T_map_imu * c.T_imu_lidar;
    lidar.information.setIdentity();
    lidar.information.topLeftCorner<3, 3>() *= 1.0 / (0.002 * 0.002);
    lidar.information.bottomRightCorner<3, 3>() *= 1.0 / (lidar_sigma_m * lidar_sigma_m);
    w.add(guess, pre, lidar);
    EXPECT_TRUE(w.solve());
    const imu::ImuState est = w.latest();
    if (t > 2.0) {  // after the biases had time to show
      r.max_position_error_m =
          std::max(r.max_position_error_m, (est.p_map_imu_m - truth.p_map_imu_m).norm());
      r.max_rotation_error_rad =
          std::max(r.max_rotation_error_rad, est.q_map_imu.angularDistance(truth.q_map_imu));
    }
    r.final_bias = est.bias;
  }
  return r;
}

TEST(SlidingWindow, RecoversAKnownBiasWithPerfectLidarPoses) {
  imu::ImuBias bias;
  bias.gyro_radps = {0.004, -0.003, 0.002};
  bias.accel_mps2 = {0.08, -0.05, 0.06};
  const Result r = run(bias, 20.0, 10, 0.01, false);
  std::printf("bias g %.5f %.5f %.5f a %.4f %.4f %.4f; max error %.4f m %.5f rad\n",
              r.final_bias.gyro_radps.x(), r.final_bias.gyro_radps.y(), r.final_bias.gyro_radps.z(),
              r.final_bias.accel_mps2.x(), r.final_bias.accel_mps2.y(), r.final_bias.accel_mps2.z(),
              r.max_position_error_m, r.max_rotation_error_rad);
  EXPECT_LT((r.final_bias.gyro_radps - bias.gyro_radps).norm(), 3e-4);
  EXPECT_LT((r.final_bias.accel_mps2 - bias.accel_mps2).norm(), 0.01);
  EXPECT_LT(r.max_position_error_m, 0.01);
}

TEST(SlidingWindow, RecoversTheBiasFromNoisyImu) {
  imu::ImuBias bias;
  bias.gyro_radps = {0.004, -0.003, 0.002};
  bias.accel_mps2 = {0.08, -0.05, 0.06};
  const Result r = run(bias, 40.0, 10, 0.02, true);
  std::printf("noisy: bias g %.5f %.5f %.5f a %.4f %.4f %.4f; max error %.4f m\n",
              r.final_bias.gyro_radps.x(), r.final_bias.gyro_radps.y(), r.final_bias.gyro_radps.z(),
              r.final_bias.accel_mps2.x(), r.final_bias.accel_mps2.y(), r.final_bias.accel_mps2.z(),
              r.max_position_error_m);
  EXPECT_LT((r.final_bias.gyro_radps - bias.gyro_radps).norm(), 2e-3);
  EXPECT_LT((r.final_bias.accel_mps2 - bias.accel_mps2).norm(), 0.04);
  EXPECT_LT(r.max_position_error_m, 0.05);
}

}  // namespace
}  // namespace posed::estimator
