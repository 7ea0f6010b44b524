#pragma once
// The ground vehicle's motion, closed-form in time so the IMU gets exact angular rate and specific
// force:
//   path   a periodic C2 cubic spline through waypoints in x-y, parameter u [m of chord length]
//   speed  u(t) from a profile of holds and quintic-smoothstep ramps (C2: stops, starts,
//          accelerations), so u̇, ü and u⃛ are closed-form
//   yaw    the path tangent's heading (the vehicle drives forwards)
//   bumps  z, roll and pitch as sums of sinusoids scaled by the current speed (a vehicle at rest
//          does not shake, which keeps the initial gravity alignment window clean)
// Derivatives: v = p'(u)u̇, a = p''(u)u̇² + p'(u)ü; body rates from the ZYX Euler rates.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "core/time.hpp"

namespace posed::sim {

/// A closed C2 cubic spline through 2D points, chord-length parametrised.
class PeriodicSpline2 {
 public:
  PeriodicSpline2() = default;
  /// At least 3 distinct points; the curve returns from the last to the first.
  explicit PeriodicSpline2(const std::vector<Eigen::Vector2d>& points_m);

  /// total parameter length (≈ loop length) [m]
  double length() const { return knots_.back(); }
  /// position, first, second and third derivative with respect to u at `u` (wrapped)
  void eval(double u, Eigen::Vector2d& p, Eigen::Vector2d& d1, Eigen::Vector2d& d2,
            Eigen::Vector2d& d3) const;
  /// waypoints as given [m]
  const std::vector<Eigen::Vector2d>& points() const { return points_; }

 private:
  std::vector<Eigen::Vector2d> points_;
  std::vector<Eigen::Vector2d> second_;  // M_i, second derivative at knot i
  std::vector<double> knots_;            // u_i, size n + 1
};

/// One speed change: from `from_mps` to `to_mps` over `duration_s`, then hold `to_mps` until
/// the next ramp starts.
struct SpeedRamp {
  /// start of the ramp [s since the trajectory starts]
  double start_s = 0;
  /// ramp length [s]
  double duration_s = 1;
  /// parameter speed before and after [m/s]
  double from_mps = 0, to_mps = 0;
  /// u at the ramp's start (filled by SpeedProfile) [m]
  double u_start_m = 0;
};

/// u(t) and its derivatives, piecewise closed-form.
class SpeedProfile {
 public:
  SpeedProfile() = default;
  /// Ramps sorted by start, non-overlapping, each starting at the previous one's `to_mps`; the
  /// speed before the first ramp is 0.
  explicit SpeedProfile(std::vector<SpeedRamp> ramps);
  /// u [m], u̇ [m/s], ü [m/s²], u⃛ [m/s³] at t [s]
  void eval(double t_s, double& u, double& ud, double& udd, double& uddd) const;
  double max_speed_mps() const { return max_speed_; }
  const std::vector<SpeedRamp>& ramps() const { return ramps_; }

 private:
  std::vector<SpeedRamp> ramps_;
  double max_speed_ = 0;
};

/// One sinusoid of the bump model.
struct Wobble {
  /// amplitude [m for z, rad for roll/pitch]
  double amplitude = 0;
  /// [rad/s]
  double omega_radps = 1;
  /// [rad]
  double phase_rad = 0;
};

struct TrajectoryConfig {
  /// height of base_link (the IMU) above the ground [m]
  double base_height_m = 0.45;
  /// gravity magnitude, map -z [m/s²]
  double gravity_mps2 = 9.805;
  /// bumps at full speed: z [m], roll [rad], pitch [rad]
  std::vector<Wobble> z_wobble, roll_wobble, pitch_wobble;
};

/// The exact state of base_link (= IMU frame) at one instant.
struct TrajectorySample {
  /// position of base_link in map [m]
  Eigen::Vector3d p_map_base_m = Eigen::Vector3d::Zero();
  /// orientation base -> map
  Eigen::Quaterniond q_map_base = Eigen::Quaterniond::Identity();
  /// velocity in map [m/s]
  Eigen::Vector3d v_map_mps = Eigen::Vector3d::Zero();
  /// acceleration in map [m/s²]
  Eigen::Vector3d a_map_mps2 = Eigen::Vector3d::Zero();
  /// angular rate of base in base axes [rad/s]
  Eigen::Vector3d w_base_radps = Eigen::Vector3d::Zero();
  /// specific force in base axes (what an ideal accelerometer reads, +g up at rest) [m/s²]
  Eigen::Vector3d f_base_mps2 = Eigen::Vector3d::Zero();
};

class Trajectory {
 public:
  Trajectory() = default;
  Trajectory(PeriodicSpline2 path, SpeedProfile speed, TrajectoryConfig config);

  /// State at `t_s` seconds after the start (true time).
  TrajectorySample at(double t_s) const;
  TrajectorySample at(Duration t) const { return at(t.seconds()); }
  /// base_link in map at `t` (a sensor's pose: T_map_base(t) * T_base_sensor).
  Eigen::Isometry3d T_map_base(Duration t) const {
    const TrajectorySample s = at(t);
    return Eigen::Translation3d(s.p_map_base_m) * s.q_map_base;
  }

  const PeriodicSpline2& path() const { return path_; }
  const SpeedProfile& speed() const { return speed_; }
  const TrajectoryConfig& config() const { return config_; }

 private:
  PeriodicSpline2 path_;
  SpeedProfile speed_;
  TrajectoryConfig config_;
};

}  // namespace posed::sim
