#pragma once
// IMU-only dead reckoning: the fusion core's output until the lidar-inertial estimator lands.
// Deterministic and clock-free: time comes only from the samples' stamps.
//
// Start-up: the rig must stand still for `init_static` (gyro below `init_max_gyro_radps`); the
// mean specific force gives roll and pitch (yaw is defined as 0), the mean rate gives the gyro
// bias. Motion during the window restarts it (counted). Then each sample is integrated with the
// midpoint rule on SO(3) x R^3, and a 9-state error covariance (attitude, velocity, position) is
// propagated from the IMU noise densities so the published covariance grows as it should.

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "core/estimator/nav_state.hpp"
#include "core/imu/static_alignment.hpp"
#include "core/measurements.hpp"

namespace posed {

struct StrapdownConfig {
  double gravity_mps2 = 9.805;  ///< [m/s^2]
  Duration init_static = Duration::from_s(1);
  double init_max_gyro_radps = 0.05;  ///< [rad/s]
  double gyro_noise_density = 0.0;    ///< [rad/s/sqrt(Hz)]
  double accel_noise_density = 0.0;   ///< [m/s^2/sqrt(Hz)]
  /// a gap longer than this between samples is not integrated across (counted) [ns]
  Duration max_gap = Duration::from_ms(100);
};

struct StrapdownCounters {
  std::uint64_t samples = 0;             ///< samples seen
  std::uint64_t out_of_order = 0;        ///< samples not newer than the previous one: skipped
  std::uint64_t gaps = 0;                ///< gaps longer than max_gap: not integrated across
  std::uint64_t alignment_restarts = 0;  ///< static windows spoiled by motion
};

class Strapdown {
 public:
  explicit Strapdown(const StrapdownConfig& config);

  /// Adds one sample; returns the propagated state once aligned, nothing while aligning or when
  /// the sample was skipped.
  std::optional<NavState> add(const ImuSample& sample);

  EstimatorMode mode() const {
    return aligned_ ? EstimatorMode::kStrapdown : EstimatorMode::kAligning;
  }
  const StrapdownCounters& counters() const { return counters_; }
  /// gyro bias estimated during alignment [rad/s]
  const Eigen::Vector3d& gyro_bias() const { return gyro_bias_; }

 private:
  void align(const imu::StaticAlignmentResult& result);
  NavState propagate(const ImuSample& sample);

  StrapdownConfig config_;
  StrapdownCounters counters_;
  bool aligned_ = false;
  imu::StaticAlignment alignment_;
  // state
  std::optional<ImuSample> previous_;
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero();
  NavState state_;
  /// error state (attitude [rad] in base_link, velocity [m/s], position [m]) in map
  Eigen::Matrix<double, 9, 9> P_ = Eigen::Matrix<double, 9, 9>::Zero();
};

}  // namespace posed
