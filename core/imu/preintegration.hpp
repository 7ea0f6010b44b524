#pragma once
// IMU preintegration on the manifold (Forster, Carlone, Dellaert, Scaramuzza 2017; seed 001
// eq. 2): the relative motion between two states i and j summarised from the IMU samples in
// between, independent of the states themselves, so an optimiser can move the states without
// re-integrating:
//   dR = prod Exp((w_k - bg) dt),  dv = sum dR_k (a_k - ba) dt,  dp = sum dv_k dt + 1/2 dR_k a dt²
// with the first-order Jacobians of dR, dv, dp with respect to the biases (a bias update is
// applied without re-integration) and the 9x9 covariance of [dphi, dv, dp] from the gyroscope and
// accelerometer white-noise densities.
//
// Integration uses the midpoint of consecutive samples (as VINS-Mono does), which is exact for
// rates that change linearly between samples; covariance and bias Jacobians use the standard
// first-order propagation. Frames: everything in the IMU frame of state i; gravity enters only in
// predict() and the residual, never in the deltas.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/measurements.hpp"
#include "core/time.hpp"

namespace posed::imu {

struct ImuNoise {
  double gyro_noise_density = 0;   ///< [rad/s/sqrt(Hz)]
  double accel_noise_density = 0;  ///< [m/s^2/sqrt(Hz)]
  double gyro_random_walk = 0;     ///< [rad/s^2/sqrt(Hz)]
  double accel_random_walk = 0;    ///< [m/s^3/sqrt(Hz)]
  /// A backup IMU's: 1 sigma per axis of its bias less the primary's, the step the bias state
  /// takes where one IMU's samples follow the other's (0 for the primary) [rad/s], [m/s^2]
  double gyro_bias_offset_radps = 0;
  double accel_bias_offset_mps2 = 0;
};

struct ImuBias {
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();  ///< [rad/s]
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();  ///< [m/s^2]
};

/// A navigation state of the IMU (base_link) frame in map.
struct ImuState {
  HostTime stamp;
  Eigen::Quaterniond q_map_imu = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_map_imu_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_map_mps = Eigen::Vector3d::Zero();  ///< velocity of the IMU in map [m/s]
  ImuBias bias;
};

/// The state's pose as a transform, T_map_imu (its quaternion normalised).
inline Eigen::Isometry3d T_map_imu(const ImuState& s) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = s.q_map_imu.normalized().toRotationMatrix();
  T.translation() = s.p_map_imu_m;
  return T;
}

class Preintegration {
 public:
  /// Starts empty at `stamp`, integrating with the biases `bias` (the linearisation point).
  Preintegration(const ImuNoise& noise, const ImuBias& bias, HostTime stamp);
  /// The same, with an interval that ends on a sample `from_backup_imu` weighed by
  /// `backup_noise` (the backup IMU's densities) instead of `noise`.
  Preintegration(const ImuNoise& noise, const ImuNoise& backup_noise, const ImuBias& bias,
                 HostTime stamp);

  /// Adds the interval from the previous sample to `sample` (the first call only sets the start
  /// sample). Samples must be in stamp order; an interval of zero or less is ignored.
  void add(const ImuSample& sample);
  /// Adds the interval [previous, t] with the sample at `t` interpolated between the previous
  /// sample and `next` (so an interval ends exactly at a measurement's stamp).
  void add_until(HostTime t, const ImuSample& next);

  /// Integrated time [s]
  double dt_s() const { return dt_s_; }
  HostTime start() const { return start_; }
  /// stamp of the last sample integrated
  HostTime end() const { return end_; }
  bool empty() const { return !have_last_ || dt_s_ <= 0; }
  const ImuSample& last_sample() const { return last_; }

  const Eigen::Matrix3d& delta_R() const { return dR_; }
  const Eigen::Vector3d& delta_v() const { return dv_; }
  const Eigen::Vector3d& delta_p() const { return dp_; }
  /// covariance of [dphi, dv, dp] [rad², (m/s)², m²]
  const Eigen::Matrix<double, 9, 9>& covariance() const { return cov_; }
  /// variance per axis of the gyroscope bias's random walk over the interval, each IMU's density
  /// over the time it measured [(rad/s)²]
  double gyro_bias_walk_variance() const;
  /// the same for the accelerometer bias [(m/s²)²]
  double accel_bias_walk_variance() const;
  /// of dt_s(), the time the backup IMU measured [s]
  double backup_dt_s() const { return backup_dt_s_; }
  /// times one IMU's sample followed the other's [1]
  int imu_switches() const { return imu_switches_; }
  const ImuBias& linearisation_bias() const { return bias_; }

  /// The deltas for other biases, to first order (bias_j - linearisation bias small).
  Eigen::Matrix3d corrected_delta_R(const Eigen::Vector3d& bg) const;
  Eigen::Vector3d corrected_delta_v(const Eigen::Vector3d& bg, const Eigen::Vector3d& ba) const;
  Eigen::Vector3d corrected_delta_p(const Eigen::Vector3d& bg, const Eigen::Vector3d& ba) const;

  /// The state at end() from `start` (stamp ignored) under gravity g_map = (0, 0, -g) [m/s²],
  /// with the biases of `start` (first-order correction); biases carry over unchanged.
  ImuState predict(const ImuState& start, double gravity_mps2) const;
  /// The same under any gravity vector in map (the map frame's own tilt estimated) [m/s²].
  ImuState predict(const ImuState& start, const Eigen::Vector3d& g_map_mps2) const;

  /// The 9-vector residual [rotation, velocity, position] of states i and j against this
  /// preintegration (Forster eq. 45), unweighted.
  Eigen::Matrix<double, 9, 1> residual(const ImuState& i, const ImuState& j,
                                       double gravity_mps2) const;

  /// Bias Jacobians, exposed for the optimiser's factor and for tests.
  const Eigen::Matrix3d& dR_dbg() const { return dR_dbg_; }
  const Eigen::Matrix3d& dv_dbg() const { return dv_dbg_; }
  const Eigen::Matrix3d& dv_dba() const { return dv_dba_; }
  const Eigen::Matrix3d& dp_dbg() const { return dp_dbg_; }
  const Eigen::Matrix3d& dp_dba() const { return dp_dba_; }

 private:
  void integrate(const ImuSample& a, const ImuSample& b);

  ImuNoise noise_, backup_noise_;
  ImuBias bias_;
  HostTime start_, end_;
  bool have_last_ = false;
  ImuSample last_;
  double dt_s_ = 0;
  double backup_dt_s_ = 0;
  int imu_switches_ = 0;
  Eigen::Matrix3d dR_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d dv_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d dp_ = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 9, 9> cov_ = Eigen::Matrix<double, 9, 9>::Zero();
  Eigen::Matrix3d dR_dbg_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d dv_dbg_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d dv_dba_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d dp_dbg_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d dp_dba_ = Eigen::Matrix3d::Zero();
};

/// The sample at `t` between `a` and `b` (linear in rates and forces).
ImuSample interpolate_sample(const ImuSample& a, const ImuSample& b, HostTime t);

}  // namespace posed::imu
