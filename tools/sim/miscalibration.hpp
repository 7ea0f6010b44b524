#pragma once
// The rig the sensors really have, off from what the configuration says (`posectl sim
// --miscalibrate`, issue 22): a real rig's extrinsics are known to about a degree and two
// centimetres, its cameras' latencies to a few milliseconds, its IMU's scale factors and axes to
// about half a percent. The simulator renders with the perturbed rig; posed runs with the
// configuration, as on a robot calibrated once and driven since. Drawn from a seed, so a run is
// repeatable, and listed in the recording's metadata, so an evaluation knows.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include "tools/sim/simulator.hpp"

namespace posed::sim {

struct Miscalibration {
  /// true = configured · error, for T_imu_lidar, T_imu_cam and T_cam_thermal
  Eigen::Isometry3d lidar_error = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d camera_error = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d thermal_error = Eigen::Isometry3d::Identity();
  /// added to the visible and thermal cameras' latencies: stamps off by this much [s]
  double visible_latency_error_s = 0;
  double thermal_latency_error_s = 0;
  /// measured = M · true, for the gyro and the accelerometer (scale on the diagonal,
  /// misalignment off it)
  Eigen::Matrix3d gyro_scale_misalignment = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d accel_scale_misalignment = Eigen::Matrix3d::Identity();

  /// One line for the metadata and the summary: every error with its unit.
  std::string describe() const;
};

/// Errors of the sizes above in seeded directions and signs: each extrinsic rotated by 1 deg about
/// a random axis and shifted by 2 cm in a random direction, each camera latency off by 2-5 ms
/// either way, each IMU matrix entry off by up to 0.5 %.
Miscalibration draw_miscalibration(std::uint64_t seed);

/// The rig the sensors really have: `rig` (as configured) with `error` applied.
void apply_miscalibration(const Miscalibration& error, SimRig& rig);

}  // namespace posed::sim
