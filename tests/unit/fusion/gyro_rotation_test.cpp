// The body rotation between two instants from the gyro, as the camera front end uses it to warp
// a thermal frame to its visible partner's stamp.

#include "core/fusion/gyro_rotation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace posed::fusion {
namespace {

ImuBuffer rotating_imu(const Eigen::Vector3d& w_radps, double seconds, double rate_hz) {
  ImuBuffer imu(ImuBufferConfig{.capacity = 4000});
  for (int k = 0; k <= static_cast<int>(seconds * rate_hz); ++k) {
    ImuSample s;
    s.stamp = HostTime::from_ns(std::llround(k * 1e9 / rate_hz));
    s.angular_velocity_radps = w_radps;
    imu.push(s);
  }
  return imu;
}

TEST(GyroRotation, AConstantRateIntegratesToItsAngleLessTheBias) {
  const Eigen::Vector3d w(0.1, -0.2, 0.5), bias(0.01, 0.02, -0.03);
  const ImuBuffer imu = rotating_imu(w, 2.0, 200.0);
  std::vector<ImuSample> scratch;
  // Between samples on both ends (1.0012 s and 1.3137 s are not on the 5 ms grid).
  const HostTime t0 = HostTime::from_ns(1'001'200'000), t1 = HostTime::from_ns(1'313'700'000);
  const auto R = gyro_rotation(imu, t0, t1, bias, scratch);
  ASSERT_TRUE(R.has_value());
  const Eigen::AngleAxisd expected(
      Eigen::AngleAxisd((w - bias).norm() * 0.3125, (w - bias).normalized()));
  EXPECT_LT((*R - expected.toRotationMatrix()).norm(), 1e-9);
  // Backwards: the inverse.
  const auto back = gyro_rotation(imu, t1, t0, bias, scratch);
  ASSERT_TRUE(back.has_value());
  EXPECT_LT((*back - R->transpose()).norm(), 1e-12);
}

TEST(GyroRotation, AVaryingRateIsIntegratedSampleBySample) {
  // w_z(t) = 2 t rad/s: the angle from 0 to T is T^2; midpoint integration of a linear rate is
  // exact.
  ImuBuffer imu(ImuBufferConfig{.capacity = 1000});
  for (int k = 0; k <= 200; ++k) {
    ImuSample s;
    s.stamp = HostTime::from_ns(k * 5'000'000);
    s.angular_velocity_radps = Eigen::Vector3d(0, 0, 2.0 * k * 0.005);
    imu.push(s);
  }
  std::vector<ImuSample> scratch;
  const auto R = gyro_rotation(imu, HostTime::from_ns(0), HostTime::from_ns(700'000'000),
                               Eigen::Vector3d::Zero(), scratch);
  ASSERT_TRUE(R.has_value());
  EXPECT_NEAR(std::atan2((*R)(1, 0), (*R)(0, 0)), 0.49, 1e-12);
}

TEST(GyroRotation, InstantsOutsideTheBufferHaveNoAnswer) {
  const ImuBuffer imu = rotating_imu(Eigen::Vector3d(0, 0, 1), 1.0, 100.0);
  std::vector<ImuSample> scratch;
  EXPECT_FALSE(gyro_rotation(imu, HostTime::from_ns(500'000'000), HostTime::from_ns(1'200'000'000),
                             Eigen::Vector3d::Zero(), scratch));
  EXPECT_FALSE(gyro_rotation(ImuBuffer(ImuBufferConfig{.capacity = 8}), HostTime::from_ns(0),
                             HostTime::from_ns(1), Eigen::Vector3d::Zero(), scratch));
}

}  // namespace
}  // namespace posed::fusion
