#pragma once
// Start-up alignment while the rig stands still: over a window of `window` with the gyro below
// `max_gyro_radps` (plus the sensor's own noise), the mean specific force is "up" in the IMU
// frame, which gives roll and pitch (yaw is defined as 0: gravity cannot observe it), and the mean
// rate is the gyro bias. Motion during the window restarts it (counted). Used by every estimator.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>

#include "core/measurements.hpp"
#include "core/time.hpp"

namespace posed::imu {

struct StaticAlignmentConfig {
  double gravity_mps2 = 9.805;            ///< [m/s^2]
  Duration window = Duration::from_s(1);  ///< how long the rig must stand still
  double max_gyro_radps = 0.05;           ///< [rad/s] above the noise allowance: motion
  double gyro_noise_density = 0.0;        ///< [rad/s/sqrt(Hz)]
  double accel_noise_density = 0.0;       ///< [m/s^2/sqrt(Hz)]
};

struct StaticAlignmentResult {
  HostTime stamp;                            ///< the last sample of the window
  Eigen::Quaterniond q_map_imu;              ///< levelled attitude, yaw 0
  Eigen::Vector3d gyro_bias_radps;           ///< mean rate over the window [rad/s]
  Eigen::Vector3d mean_specific_force_mps2;  ///< [m/s^2]
  double tilt_sigma_rad = 0;  ///< 1-sigma of roll and pitch from the window's noise [rad]
  std::uint64_t samples = 0;  ///< samples averaged
};

class StaticAlignment {
 public:
  explicit StaticAlignment(const StaticAlignmentConfig& config) : config_(config) {}
  /// Feeds one sample; the result once a still window is complete (then again for every later
  /// sample until reset()).
  std::optional<StaticAlignmentResult> add(const ImuSample& sample);
  void reset();
  /// windows spoiled by motion
  std::uint64_t restarts() const { return restarts_; }

 private:
  StaticAlignmentConfig config_;
  std::optional<HostTime> previous_stamp_;
  HostTime window_start_;
  Eigen::Vector3d sum_f_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_w_ = Eigen::Vector3d::Zero();
  std::uint64_t samples_ = 0;
  std::uint64_t restarts_ = 0;
};

}  // namespace posed::imu
