#include "core/estimator/odometry_propagator.hpp"

#include <algorithm>

#include "core/math/so3.hpp"

namespace posed::estimator {

OdometryPropagator::OdometryPropagator(const OdometryPropagatorConfig& config)
    : config_(config), history_(ImuBufferConfig{.capacity = config.history_samples}) {
  scratch_.reserve(history_.capacity() + 2);
}

imu::ImuState OdometryPropagator::step(const imu::ImuState& state, const ImuSample& from,
                                       const ImuSample& to) const {
  imu::Preintegration pre(imu::ImuNoise{}, state.bias, from.stamp);
  pre.add(from);
  pre.add(to);
  imu::ImuState next = gravity_map_mps2_.isZero() ? pre.predict(state, config_.gravity_mps2)
                                                  : pre.predict(state, gravity_map_mps2_);
  next.stamp = to.stamp;
  return next;
}

void OdometryPropagator::set_anchor(const NavState& anchor) {
  if (anchor_ && anchor.stamp < anchor_->stamp) return;
  anchor_ = anchor;
  ++figures_.anchors;
  propagated_.stamp = anchor.stamp;
  propagated_.p_map_imu_m = anchor.p_map_base_m;
  propagated_.q_map_imu = anchor.q_map_base;
  propagated_.v_map_mps = anchor.v_map_mps;
  propagated_.bias.gyro_radps = anchor.gyro_bias_radps;
  propagated_.bias.accel_mps2 = anchor.accel_bias_mps2;
  gravity_map_mps2_ = anchor.gravity_map_mps2;
  last_.reset();
  // Integrate again through the samples since the anchor: they were published from the old one.
  if (!history_.empty()) {
    if (history_.oldest_stamp() > anchor.stamp) ++figures_.stale_anchors;
    history_.samples_between(anchor.stamp, history_.newest_stamp(), scratch_);
    for (std::size_t i = 0; i < scratch_.size(); ++i) {
      const ImuSample& s = scratch_[i];
      if (!last_) {
        // Start exactly at the anchor: between the bracket below it and the next sample.
        if (s.stamp < anchor.stamp && i + 1 < scratch_.size()) {
          last_ = imu::interpolate_sample(s, scratch_[i + 1], anchor.stamp);
        } else if (s.stamp < anchor.stamp) {
          last_ = s;  // the anchor is past every sample held: start from it as it is
          last_->stamp = anchor.stamp;
        } else {
          last_ = s;
          if (s.stamp > anchor.stamp) {
            last_->stamp = anchor.stamp;  // extrapolated back, only for a stale anchor
            propagated_ = step(propagated_, *last_, s);
            last_ = s;
          }
        }
        continue;
      }
      if (s.stamp <= last_->stamp) continue;
      propagated_ = step(propagated_, *last_, s);
      last_ = s;
    }
  }
  // The correction: where odometry now says the newest sample was, against what was published
  // for it. Published = propagated + offset, so the offset that keeps the output where it was
  // is the difference; it then shrinks to zero over blend_s.
  if (!published_ || !last_ || published_->stamp != propagated_.stamp) {
    offset_p_m_.setZero();
    offset_rot_rad_.setZero();
    return;
  }
  const Eigen::Vector3d dp = published_->p_map_base_m - propagated_.p_map_imu_m;
  const Eigen::Vector3d drot = so3::log(published_->q_map_base * propagated_.q_map_imu.conjugate());
  figures_.last_correction_m = dp.norm();
  figures_.last_correction_rad = drot.norm();
  figures_.max_correction_m = std::max(figures_.max_correction_m, dp.norm());
  if (config_.blend_s <= 0 || dp.norm() > config_.snap_m || drot.norm() > config_.snap_rad) {
    if (config_.blend_s > 0) ++figures_.snaps;
    offset_p_m_.setZero();
    offset_rot_rad_.setZero();
    return;
  }
  offset_p_m_ = dp;
  offset_rot_rad_ = drot;
  blend_start_ = propagated_.stamp;
}

NavState OdometryPropagator::output(const ImuSample& sample) {
  NavState out;
  out.stamp = propagated_.stamp;
  double remaining = 0;  // share of the offset still applied
  if (config_.blend_s > 0 && (!offset_p_m_.isZero(0) || !offset_rot_rad_.isZero(0))) {
    remaining =
        std::clamp(1.0 - (propagated_.stamp - blend_start_).seconds() / config_.blend_s, 0.0, 1.0);
    if (remaining == 0) {
      offset_p_m_.setZero();
      offset_rot_rad_.setZero();
    }
  }
  out.p_map_base_m = propagated_.p_map_imu_m + remaining * offset_p_m_;
  out.q_map_base = (so3::exp_q(remaining * offset_rot_rad_) * propagated_.q_map_imu).normalized();
  out.v_map_mps = propagated_.v_map_mps;
  out.w_base_radps = sample.angular_velocity_radps - propagated_.bias.gyro_radps;
  out.gyro_bias_radps = propagated_.bias.gyro_radps;
  out.accel_bias_mps2 = propagated_.bias.accel_mps2;
  // Uncertainty grows from the anchor's with the IMU's white noise (random-walk model); a
  // rotation variance added equally on every axis is the same in map-fixed and body axes.
  out.pose_covariance = anchor_->pose_covariance;
  const double dt = (propagated_.stamp - anchor_->stamp).seconds();
  const bool backup = sample.from_backup_imu && config_.backup_accel_noise_density > 0;
  const double sa = backup ? config_.backup_accel_noise_density : config_.accel_noise_density;
  const double sg = backup ? config_.backup_gyro_noise_density : config_.gyro_noise_density;
  out.pose_covariance.topLeftCorner<3, 3>().diagonal().array() += sa * sa * dt * dt * dt / 3.0;
  out.pose_covariance.bottomRightCorner<3, 3>().diagonal().array() += sg * sg * dt;
  out.twist_covariance = anchor_->twist_covariance;
  out.mode = anchor_->mode;
  out.optimised = false;
  out.sequence = ++sequence_;
  published_ = out;
  return out;
}

bool OdometryPropagator::add_imu(const ImuSample& sample, NavState& out) {
  const ImuPushResult pushed = history_.push(sample);
  if (pushed != ImuPushResult::kAccepted && pushed != ImuPushResult::kAcceptedOverwrote) {
    return false;
  }
  if (!anchor_) return false;
  if (!last_) {
    // The first sample after an anchor that no held sample reached past.
    if (sample.stamp <= anchor_->stamp) return false;
    ImuSample start = sample;
    start.stamp = anchor_->stamp;
    propagated_ = step(propagated_, start, sample);
  } else if (sample.stamp > last_->stamp) {
    propagated_ = step(propagated_, *last_, sample);
  } else {
    return false;
  }
  last_ = sample;
  out = output(sample);
  return true;
}

}  // namespace posed::estimator
