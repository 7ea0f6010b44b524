#include "core/imu/preintegration.hpp"

#include "core/math/so3.hpp"

namespace posed::imu {

using so3::skew;

ImuSample interpolate_sample(const ImuSample& a, const ImuSample& b, HostTime t) {
  const double span = static_cast<double>((b.stamp - a.stamp).ns);
  const double s = span > 0 ? static_cast<double>((t - a.stamp).ns) / span : 0.0;
  ImuSample out = a;
  out.stamp = t;
  out.from_backup_imu = b.from_backup_imu;  // [a, t] is part of [a, b], which b's IMU measured
  out.angular_velocity_radps =
      a.angular_velocity_radps + s * (b.angular_velocity_radps - a.angular_velocity_radps);
  out.specific_force_mps2 =
      a.specific_force_mps2 + s * (b.specific_force_mps2 - a.specific_force_mps2);
  return out;
}

Preintegration::Preintegration(const ImuNoise& noise, const ImuBias& bias, HostTime stamp)
    : Preintegration(noise, noise, bias, stamp) {}

Preintegration::Preintegration(const ImuNoise& noise, const ImuNoise& backup_noise,
                               const ImuBias& bias, HostTime stamp)
    : noise_(noise), backup_noise_(backup_noise), bias_(bias), start_(stamp), end_(stamp) {}

void Preintegration::add(const ImuSample& sample) {
  if (!have_last_) {
    last_ = sample;
    have_last_ = true;
    start_ = end_ = sample.stamp;
    return;
  }
  if (sample.stamp <= last_.stamp) return;
  integrate(last_, sample);
  last_ = sample;
  end_ = sample.stamp;
}

void Preintegration::add_until(HostTime t, const ImuSample& next) {
  if (!have_last_ || t <= last_.stamp) return;
  add(interpolate_sample(last_, next, t));
}

void Preintegration::integrate(const ImuSample& a, const ImuSample& b) {
  const double dt = (b.stamp - a.stamp).seconds();
  const Eigen::Vector3d w =
      0.5 * (a.angular_velocity_radps + b.angular_velocity_radps) - bias_.gyro_radps;
  const Eigen::Vector3d acc_a = a.specific_force_mps2 - bias_.accel_mps2;
  const Eigen::Vector3d acc_b = b.specific_force_mps2 - bias_.accel_mps2;

  const Eigen::Matrix3d dR_inc = so3::exp(w * dt);
  const Eigen::Matrix3d dR_next = dR_ * dR_inc;
  // Midpoint in the frame of state i: the force at both ends rotated by the attitude there.
  const Eigen::Vector3d acc_i = 0.5 * (dR_ * acc_a + dR_next * acc_b);
  const Eigen::Vector3d acc_mid = 0.5 * (acc_a + acc_b);  // in the frame at k, for Jacobians

  // Noise and bias Jacobians with the first-order propagation (Forster, appendix A).
  const Eigen::Matrix3d Jr = so3::right_jacobian(w * dt);
  const Eigen::Matrix3d dR_acc_x = dR_ * skew(acc_mid);
  Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Identity();
  A.block<3, 3>(0, 0) = dR_inc.transpose();
  A.block<3, 3>(3, 0) = -dR_acc_x * dt;
  A.block<3, 3>(6, 0) = -0.5 * dR_acc_x * dt * dt;
  A.block<3, 3>(6, 3) = Eigen::Matrix3d::Identity() * dt;
  Eigen::Matrix<double, 9, 6> B = Eigen::Matrix<double, 9, 6>::Zero();
  B.block<3, 3>(0, 0) = Jr * dt;
  B.block<3, 3>(3, 3) = dR_ * dt;
  B.block<3, 3>(6, 3) = 0.5 * dR_ * dt * dt;
  Eigen::Matrix<double, 6, 6> Q = Eigen::Matrix<double, 6, 6>::Zero();
  // Continuous white-noise densities become a per-sample variance sigma² / dt; the interval is
  // the IMU's that measured its end sample.
  const ImuNoise& n = b.from_backup_imu ? backup_noise_ : noise_;
  Q.block<3, 3>(0, 0).diagonal().setConstant(n.gyro_noise_density * n.gyro_noise_density / dt);
  Q.block<3, 3>(3, 3).diagonal().setConstant(n.accel_noise_density * n.accel_noise_density / dt);
  if (b.from_backup_imu) backup_dt_s_ += dt;
  if (b.from_backup_imu != a.from_backup_imu) ++imu_switches_;
  cov_ = A * cov_ * A.transpose() + B * Q * B.transpose();

  // Bias Jacobians of the midpoint step itself (as the deltas are integrated), so a bias update
  // by the Jacobians matches re-integration to second order. Perturbing R by R Exp(d) moves R a
  // by -R [a]x d.
  const Eigen::Matrix3d dR_dbg_next = dR_inc.transpose() * dR_dbg_ - Jr * dt;
  const Eigen::Matrix3d dacc_dbg =
      -0.5 * (dR_ * skew(acc_a) * dR_dbg_ + dR_next * skew(acc_b) * dR_dbg_next);
  const Eigen::Matrix3d dacc_dba = -0.5 * (dR_ + dR_next);
  dp_dbg_ += dv_dbg_ * dt + 0.5 * dacc_dbg * dt * dt;
  dp_dba_ += dv_dba_ * dt + 0.5 * dacc_dba * dt * dt;
  dv_dbg_ += dacc_dbg * dt;
  dv_dba_ += dacc_dba * dt;
  dR_dbg_ = dR_dbg_next;

  dp_ += dv_ * dt + 0.5 * acc_i * dt * dt;
  dv_ += acc_i * dt;
  dR_ = dR_next;
  // Keep dR a rotation: re-orthonormalise (drift over thousands of products is measurable).
  dR_ = Eigen::Quaterniond(dR_).normalized().toRotationMatrix();
  dt_s_ += dt;
}

double Preintegration::gyro_bias_walk_variance() const {
  const double rw = noise_.gyro_random_walk, backup_rw = backup_noise_.gyro_random_walk;
  const double offset = backup_noise_.gyro_bias_offset_radps;
  return rw * rw * (dt_s_ - backup_dt_s_) + backup_rw * backup_rw * backup_dt_s_ +
         imu_switches_ * offset * offset;
}

double Preintegration::accel_bias_walk_variance() const {
  const double rw = noise_.accel_random_walk, backup_rw = backup_noise_.accel_random_walk;
  const double offset = backup_noise_.accel_bias_offset_mps2;
  return rw * rw * (dt_s_ - backup_dt_s_) + backup_rw * backup_rw * backup_dt_s_ +
         imu_switches_ * offset * offset;
}

Eigen::Matrix3d Preintegration::corrected_delta_R(const Eigen::Vector3d& bg) const {
  return dR_ * so3::exp(dR_dbg_ * (bg - bias_.gyro_radps));
}

Eigen::Vector3d Preintegration::corrected_delta_v(const Eigen::Vector3d& bg,
                                                  const Eigen::Vector3d& ba) const {
  return dv_ + dv_dbg_ * (bg - bias_.gyro_radps) + dv_dba_ * (ba - bias_.accel_mps2);
}

Eigen::Vector3d Preintegration::corrected_delta_p(const Eigen::Vector3d& bg,
                                                  const Eigen::Vector3d& ba) const {
  return dp_ + dp_dbg_ * (bg - bias_.gyro_radps) + dp_dba_ * (ba - bias_.accel_mps2);
}

ImuState Preintegration::predict(const ImuState& s, double gravity_mps2) const {
  return predict(s, Eigen::Vector3d(0, 0, -gravity_mps2));
}

ImuState Preintegration::predict(const ImuState& s, const Eigen::Vector3d& g) const {
  const Eigen::Matrix3d Ri = s.q_map_imu.toRotationMatrix();
  const Eigen::Vector3d& bg = s.bias.gyro_radps;
  const Eigen::Vector3d& ba = s.bias.accel_mps2;
  ImuState out = s;
  out.stamp = end_;
  out.q_map_imu = Eigen::Quaterniond(Ri * corrected_delta_R(bg)).normalized();
  out.v_map_mps = s.v_map_mps + g * dt_s_ + Ri * corrected_delta_v(bg, ba);
  out.p_map_imu_m = s.p_map_imu_m + s.v_map_mps * dt_s_ + 0.5 * g * dt_s_ * dt_s_ +
                    Ri * corrected_delta_p(bg, ba);
  return out;
}

Eigen::Matrix<double, 9, 1> Preintegration::residual(const ImuState& i, const ImuState& j,
                                                     double gravity_mps2) const {
  const Eigen::Vector3d g(0, 0, -gravity_mps2);
  const Eigen::Matrix3d Ri_T = i.q_map_imu.toRotationMatrix().transpose();
  const Eigen::Vector3d& bg = i.bias.gyro_radps;
  const Eigen::Vector3d& ba = i.bias.accel_mps2;
  Eigen::Matrix<double, 9, 1> r;
  r.segment<3>(0) = so3::log(
      Eigen::Matrix3d(corrected_delta_R(bg).transpose() * Ri_T * j.q_map_imu.toRotationMatrix()));
  r.segment<3>(3) = Ri_T * (j.v_map_mps - i.v_map_mps - g * dt_s_) - corrected_delta_v(bg, ba);
  r.segment<3>(6) =
      Ri_T * (j.p_map_imu_m - i.p_map_imu_m - i.v_map_mps * dt_s_ - 0.5 * g * dt_s_ * dt_s_) -
      corrected_delta_p(bg, ba);
  return r;
}

}  // namespace posed::imu
