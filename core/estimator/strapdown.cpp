#include "core/estimator/strapdown.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace posed {
namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Eigen::Quaterniond exp_so3(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (angle < 1e-12)
    return Eigen::Quaterniond(1, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z()).normalized();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, phi / angle));
}

}  // namespace

Strapdown::Strapdown(const StrapdownConfig& config) : config_(config) {}

std::optional<NavState> Strapdown::add(const ImuSample& sample) {
  ++counters_.samples;
  if (previous_ && sample.stamp <= previous_->stamp) {
    ++counters_.out_of_order;
    return std::nullopt;
  }
  if (!aligned_) {
    align(sample);
    previous_ = sample;
    if (!aligned_) return std::nullopt;
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

void Strapdown::align(const ImuSample& sample) {
  const Eigen::Vector3d w = sample.angular_velocity_radps;
  if (window_samples_ == 0) window_start_ = sample.stamp;
  // "Still" allows the sensor's own white noise per sample (4 sigma of the 3-axis norm), so a
  // noisy but static IMU does not keep restarting the window.
  const double dt = previous_ ? std::max((sample.stamp - previous_->stamp).seconds(), 1e-4) : 0.01;
  const double noise_radps = 4.0 * std::sqrt(3.0) * config_.gyro_noise_density / std::sqrt(dt);
  if (w.norm() > config_.init_max_gyro_radps + noise_radps) {
    if (window_samples_ > 0) ++counters_.alignment_restarts;
    sum_f_.setZero();
    sum_w_.setZero();
    window_samples_ = 0;
    return;
  }
  sum_f_ += sample.specific_force_mps2;
  sum_w_ += w;
  ++window_samples_;
  if (sample.stamp - window_start_ < config_.init_static) return;

  const Eigen::Vector3d f_mean = sum_f_ / static_cast<double>(window_samples_);
  gyro_bias_ = sum_w_ / static_cast<double>(window_samples_);
  // At rest the accelerometer reads the reaction to gravity: "up" in the body frame. The smallest
  // rotation taking it to map +z levels the body and leaves yaw at 0 (unobservable from gravity).
  state_.q_map_base =
      Eigen::Quaterniond::FromTwoVectors(f_mean.normalized(), Eigen::Vector3d::UnitZ());
  state_.p_map_base_m.setZero();
  state_.v_map_mps.setZero();
  state_.mode = EstimatorMode::kStrapdown;
  // Initial uncertainty: tilt from the mean's noise, yaw unknown but defined (small), rest zero.
  const double n = static_cast<double>(window_samples_);
  const double tilt_sigma =
      std::max(1e-4, config_.accel_noise_density / config_.gravity_mps2 / std::sqrt(n));
  P_.setZero();
  P_.block<2, 2>(0, 0) = Eigen::Matrix2d::Identity() * tilt_sigma * tilt_sigma;
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
  const Eigen::Quaterniond q_now = (q_prev * exp_so3(w_mid * dt)).normalized();
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
  F.block<3, 3>(0, 0) = exp_so3(-w_mid * dt).toRotationMatrix();
  F.block<3, 3>(3, 0) = -R * skew(prev.specific_force_mps2) * dt;
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
