#pragma once
// A known ground-vehicle motion for the synthetic IMU and for checking what posed estimates from
// it: stand still (so the gravity alignment has a static window), accelerate smoothly onto a
// circle, then drive it at constant speed. Closed-form, so tests compare against exact values.
//
// World frame `map`: x east, y north, z up, gravity (0, 0, -g). The body (base_link = IMU frame,
// x forward, y left, z up) starts at the origin heading +x and turns left around (0, R, 0).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/time.hpp"

namespace posed::sim {

struct CircleMotionConfig {
  double radius_m = 5.0;   ///< [m]
  double speed_mps = 1.0;  ///< cruise speed [m/s]
  double static_s = 2.0;   ///< standing still before moving [s]
  double ramp_s = 3.0;     ///< smoothstep acceleration to cruise speed [s]
  double gravity_mps2 = 9.805;
};

/// The exact state of the body at one instant.
struct MotionSample {
  Eigen::Vector3d p_map_base_m;
  Eigen::Quaterniond q_map_base;
  Eigen::Vector3d v_map_mps;
  /// angular rate of the body in the body frame [rad/s]
  Eigen::Vector3d w_base_radps;
  /// specific force (what an ideal accelerometer reads) in the body frame [m/s^2]
  Eigen::Vector3d f_base_mps2;
};

class CircleMotion {
 public:
  explicit CircleMotion(const CircleMotionConfig& config) : c_(config) {}

  /// The state `t` after the motion starts.
  MotionSample at(Duration t) const;

 private:
  CircleMotionConfig c_;
};

}  // namespace posed::sim
