#pragma once
// The estimator's output: the pose of base_link in map, with velocity and uncertainty.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string_view>

#include "core/time.hpp"

namespace posed {

enum class EstimatorMode : std::uint8_t {
  kAligning,       ///< collecting the static window for the gravity alignment; no pose yet
  kStrapdown,      ///< IMU-only dead reckoning: drifts without bound, no aiding
  kLidarInertial,  ///< lidar-inertial odometry, every direction constrained by the scans
  kDegenerate,     ///< lidar-inertial, some direction unconstrained by the last scan (IMU holds it)
  kReinitialising,  ///< diverged: restarting the window from the last lidar pose
};

constexpr std::string_view to_string(EstimatorMode m) {
  switch (m) {
    case EstimatorMode::kAligning:
      return "aligning";
    case EstimatorMode::kStrapdown:
      return "strapdown";
    case EstimatorMode::kLidarInertial:
      return "lidar_inertial";
    case EstimatorMode::kDegenerate:
      return "degenerate";
    case EstimatorMode::kReinitialising:
      return "reinitialising";
  }
  return "unknown";
}

struct NavState {
  /// host clock
  HostTime stamp;
  Eigen::Vector3d p_map_base_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_map_base = Eigen::Quaterniond::Identity();
  /// velocity of base_link in map [m/s]
  Eigen::Vector3d v_map_mps = Eigen::Vector3d::Zero();
  /// bias-corrected angular rate in base_link [rad/s]
  Eigen::Vector3d w_base_radps = Eigen::Vector3d::Zero();
  /// pose covariance, ROS order (x, y, z, rot x, rot y, rot z), map-fixed axes [m^2, rad^2]
  Eigen::Matrix<double, 6, 6> pose_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  /// twist covariance, ROS order (vx, vy, vz, wx, wy, wz) in base_link [(m/s)^2, (rad/s)^2]
  Eigen::Matrix<double, 6, 6> twist_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  EstimatorMode mode = EstimatorMode::kStrapdown;
  /// a state the back end optimised (rt/posed/pose); otherwise IMU propagation (rt/posed/odom)
  bool optimised = false;
  /// increments with every state
  std::uint64_t sequence = 0;
  /// IMU propagation may start from this state (daemon/pipeline/odometry_path.hpp): every
  /// optimised state, and the first state after the alignment
  bool anchor = false;
  /// the biases the state was estimated with [rad/s], [m/s^2]
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();
  /// gravity in map as the state was estimated with, when the estimator estimates the map's
  /// tilt; zero: (0, 0, -g) [m/s^2]
  Eigen::Vector3d gravity_map_mps2 = Eigen::Vector3d::Zero();
  /// host receive time of the newest sample that went into the state (the Source's receive
  /// stamp; set by the pipeline, unset by the cores), for latency figures
  HostTime received;
};

}  // namespace posed
