#pragma once
// A smooth 3-D motion with closed-form position and attitude, and the ideal IMU samples it
// produces (angular rate by a central difference on SO(3), accurate to ~1e-9 rad/s; specific force
// from the analytic acceleration), for checking integrators against ground truth.

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "core/imu/preintegration.hpp"
#include "core/math/so3.hpp"
#include "core/measurements.hpp"

namespace posed::test {

struct AnalyticMotion {
  double gravity_mps2 = 9.81;

  Eigen::Vector3d p(double t) const {
    return {4.0 * std::sin(0.5 * t), 3.0 * std::cos(0.4 * t) - 3.0, 0.3 * std::sin(1.1 * t)};
  }
  Eigen::Vector3d v(double t) const {
    return {2.0 * std::cos(0.5 * t), -1.2 * std::sin(0.4 * t), 0.33 * std::cos(1.1 * t)};
  }
  Eigen::Vector3d a(double t) const {
    return {-1.0 * std::sin(0.5 * t), -0.48 * std::cos(0.4 * t), -0.363 * std::sin(1.1 * t)};
  }
  Eigen::Matrix3d R(double t) const {
    return so3::exp(Eigen::Vector3d(0.2 * std::sin(0.7 * t), 0.15 * std::cos(0.9 * t) - 0.15,
                                    0.6 * t + 0.1 * std::sin(1.3 * t)));
  }
  Eigen::Vector3d w_body(double t) const {
    const double h = 1e-5;
    return so3::log(Eigen::Matrix3d(R(t - h).transpose() * R(t + h))) / (2 * h);
  }
  ImuSample sample(double t) const {
    ImuSample s;
    s.stamp = HostTime::from_ns(static_cast<std::int64_t>(std::llround(t * 1e9)));
    s.angular_velocity_radps = w_body(t);
    s.specific_force_mps2 = R(t).transpose() * (a(t) - Eigen::Vector3d(0, 0, -gravity_mps2));
    return s;
  }
  imu::ImuState state(double t) const {
    imu::ImuState s;
    s.stamp = HostTime::from_ns(static_cast<std::int64_t>(std::llround(t * 1e9)));
    s.q_map_imu = Eigen::Quaterniond(R(t));
    s.p_map_imu_m = p(t);
    s.v_map_mps = v(t);
    return s;
  }
};

}  // namespace posed::test
