#include "core/imu/moving_alignment.hpp"

#include "core/math/so3.hpp"

namespace posed::imu {

void MovingAlignment::reset() {
  previous_.reset();
  q_start_now_.setIdentity();
  sum_f_start_.setZero();
  samples_ = 0;
}

std::optional<StaticAlignmentResult> MovingAlignment::add(const ImuSample& sample) {
  if (!previous_) {
    start_ = sample.stamp;
    previous_ = sample;
    sum_f_start_ = sample.specific_force_mps2;
    samples_ = 1;
    return std::nullopt;
  }
  if (sample.stamp <= previous_->stamp) return std::nullopt;
  const double dt = (sample.stamp - previous_->stamp).seconds();
  const Eigen::Vector3d w =
      0.5 * (previous_->angular_velocity_radps + sample.angular_velocity_radps);
  q_start_now_ = (q_start_now_ * so3::exp_q(w * dt)).normalized();
  sum_f_start_ += q_start_now_ * sample.specific_force_mps2;
  ++samples_;
  previous_ = sample;
  if (sample.stamp - start_ < config_.window) return std::nullopt;

  StaticAlignmentResult r;
  r.stamp = sample.stamp;
  r.samples = samples_;
  r.mean_specific_force_mps2 =
      q_start_now_.conjugate() * (sum_f_start_ / static_cast<double>(samples_));
  r.q_map_imu = Eigen::Quaterniond::FromTwoVectors(r.mean_specific_force_mps2.normalized(),
                                                   Eigen::Vector3d::UnitZ());
  r.gyro_bias_radps.setZero();
  // What is left of the acceleration after averaging: the norm's departure from g is a lower
  // bound on it; a mean of 0.3 m/s² would tilt the estimate by 1.75 deg.
  const double excess = std::abs(r.mean_specific_force_mps2.norm() - config_.gravity_mps2);
  r.tilt_sigma_rad = std::max(0.03, excess / config_.gravity_mps2);
  return r;
}

}  // namespace posed::imu
