#include "core/imu/static_alignment.hpp"

#include <algorithm>
#include <cmath>

namespace posed::imu {

void StaticAlignment::reset() {
  previous_stamp_.reset();
  sum_f_.setZero();
  sum_w_.setZero();
  samples_ = 0;
}

std::optional<StaticAlignmentResult> StaticAlignment::add(const ImuSample& sample) {
  const Eigen::Vector3d& w = sample.angular_velocity_radps;
  // "Still" allows the sensor's own white noise per sample (4 sigma of the 3-axis norm), so a
  // noisy but static IMU does not keep restarting the window.
  const double dt =
      previous_stamp_ ? std::max((sample.stamp - *previous_stamp_).seconds(), 1e-4) : 0.01;
  previous_stamp_ = sample.stamp;
  const double noise_radps = 4.0 * std::sqrt(3.0) * config_.gyro_noise_density / std::sqrt(dt);
  if (w.norm() > config_.max_gyro_radps + noise_radps) {
    if (samples_ > 0) ++restarts_;
    sum_f_.setZero();
    sum_w_.setZero();
    samples_ = 0;
    return std::nullopt;
  }
  if (samples_ == 0) window_start_ = sample.stamp;
  sum_f_ += sample.specific_force_mps2;
  sum_w_ += w;
  ++samples_;
  if (sample.stamp - window_start_ < config_.window) return std::nullopt;

  StaticAlignmentResult r;
  r.stamp = sample.stamp;
  r.samples = samples_;
  const double n = static_cast<double>(samples_);
  r.mean_specific_force_mps2 = sum_f_ / n;
  r.gyro_bias_radps = sum_w_ / n;
  // At rest the accelerometer reads the reaction to gravity: "up" in the IMU frame. The smallest
  // rotation taking it to map +z levels the IMU and leaves yaw at 0.
  r.q_map_imu = Eigen::Quaterniond::FromTwoVectors(r.mean_specific_force_mps2.normalized(),
                                                   Eigen::Vector3d::UnitZ());
  r.tilt_sigma_rad =
      std::max(1e-4, config_.accel_noise_density / config_.gravity_mps2 / std::sqrt(n));
  return r;
}

}  // namespace posed::imu
