#include "core/estimator/strapdown.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "core/math/so3.hpp"

namespace posed {

Strapdown::Strapdown(const StrapdownConfig& config)
    : config_(config),
      alignment_(imu::StaticAlignmentConfig{.gravity_mps2 = config.gravity_mps2,
                                            .window = config.init_static,
                                            .max_gyro_radps = config.init_max_gyro_radps,
                                            .gyro_noise_density = config.gyro_noise_density,
                                            .accel_noise_density = config.accel_noise_density}) {}

std::optional<NavState> Strapdown::add(const ImuSample& sample) {
  ++counters_.samples;
  if (previous_ && sample.stamp <= previous_->stamp) {
    ++counters_.out_of_order;
    return std::nullopt;
  }
  if (!aligned_) {
    const auto result = alignment_.add(sample);
    counters_.alignment_restarts = alignment_.restarts();
    previous_ = sample;
    if (!result) return std::nullopt;
    align(*result);
    state_.stamp = sample.stamp;
    state_.w_base_radps = sample.angular_velocity_radps - gyro_bias_;
    return state_;
  }
  if (sample.stamp - previous_->stamp > config_.max_gap) {
    // Integrating across a long gap would invent motion; restart from here, keeping the state.
    ++counters_.gaps;
    previous_ = sample;
    state_.stamp = sample.stamp;
    return std::nullopt;
  }
  NavState out = propagate(sample);
  previous_ = sample;
  return out;
}

void Strapdown::align(const imu::StaticAlignmentResult& result) {
  gyro_bias_ = result.gyro_bias_radps;
  state_.q_map_base = result.q_map_imu;
  state_.p_map_base_m.setZero();
  state_.v_map_mps.setZero();
  state_.mode = EstimatorMode::kStrapdown;
  // Initial uncertainty: tilt from the mean's noise, yaw unknown but defined (small), rest zero.
  P_.setZero();
  P_.block<2, 2>(0, 0) =
      Eigen::Matrix2d::Identity() * result.tilt_sigma_rad * result.tilt_sigma_rad;
  P_(2, 2) = 1e-6;
  aligned_ = true;
}

NavState Strapdown::propagate(const ImuSample& sample) {
  const ImuSample& prev = *previous_;
  const double dt = (sample.stamp - prev.stamp).seconds();
  const Eigen::Vector3d g_map(0, 0, -config_.gravity_mps2);

  const Eigen::Vector3d w_prev = prev.angular_velocity_radps - gyro_bias_;
  const Eigen::Vector3d w_now = sample.angular_velocity_radps - gyro_bias_;
  const Eigen::Vector3d w_mid = 0.5 * (w_prev + w_now);

  const Eigen::Quaterniond q_prev = state_.q_map_base;
  const Eigen::Quaterniond q_now = (q_prev * so3::exp_q(w_mid * dt)).normalized();
  const Eigen::Vector3d a_prev = q_prev * prev.specific_force_mps2 + g_map;
  const Eigen::Vector3d a_now = q_now * sample.specific_force_mps2 + g_map;
  const Eigen::Vector3d a_mid = 0.5 * (a_prev + a_now);

  state_.p_map_base_m += state_.v_map_mps * dt + 0.5 * a_mid * dt * dt;
  state_.v_map_mps += a_mid * dt;
  state_.q_map_base = q_now;
  state_.w_base_radps = w_now;
  state_.stamp = sample.stamp;
  ++state_.sequence;

  // Error-state covariance (right-perturbed attitude): x = [dtheta, dv, dp].
  const Eigen::Matrix3d R = q_prev.toRotationMatrix();
  Eigen::Matrix<double, 9, 9> F = Eigen::Matrix<double, 9, 9>::Identity();
  F.block<3, 3>(0, 0) = so3::exp(-w_mid * dt);
  F.block<3, 3>(3, 0) = -R * so3::skew(prev.specific_force_mps2) * dt;
  F.block<3, 3>(6, 3) = Eigen::Matrix3d::Identity() * dt;
  Eigen::Matrix<double, 9, 9> Q = Eigen::Matrix<double, 9, 9>::Zero();
  const double sg2 = config_.gyro_noise_density * config_.gyro_noise_density;
  const double sa2 = config_.accel_noise_density * config_.accel_noise_density;
  Q.block<3, 3>(0, 0) = Eigen::Matrix3d::Identity() * sg2 * dt;
  Q.block<3, 3>(3, 3) = Eigen::Matrix3d::Identity() * sa2 * dt;
  P_ = F * P_ * F.transpose() + Q;

  // ROS pose covariance: position, then rotation about map-fixed axes (R * dtheta).
  const Eigen::Matrix3d Rn = q_now.toRotationMatrix();
  state_.pose_covariance.setZero();
  state_.pose_covariance.block<3, 3>(0, 0) = P_.block<3, 3>(6, 6);
  state_.pose_covariance.block<3, 3>(3, 3) = Rn * P_.block<3, 3>(0, 0) * Rn.transpose();
  state_.pose_covariance.block<3, 3>(0, 3) = P_.block<3, 3>(6, 0) * Rn.transpose();
  state_.pose_covariance.block<3, 3>(3, 0) = state_.pose_covariance.block<3, 3>(0, 3).transpose();
  state_.twist_covariance.setZero();
  state_.twist_covariance.block<3, 3>(0, 0) = Rn.transpose() * P_.block<3, 3>(3, 3) * Rn;
  // Rate noise over one sample interval.
  state_.twist_covariance.block<3, 3>(3, 3) =
      Eigen::Matrix3d::Identity() * sg2 / std::max(dt, 1e-6);
  return state_;
}

}  // namespace posed
