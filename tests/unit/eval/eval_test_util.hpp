#pragma once
// Helpers for the eval tests: synthetic trajectories and the real-data folder.

#include <Eigen/Geometry>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/common/realdata.hpp"
#include "tools/eval/trajectory.hpp"

namespace posed::eval::test {

/// The real-data folder (tests/common/realdata.hpp).
using ::posed::test::realdata_dir;

inline Eigen::Matrix3d rot(double roll_rad, double pitch_rad, double yaw_rad) {
  return (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// Appends a stamped pose.
inline void add_pose(Trajectory& t, double stamp_s, const Eigen::Vector3d& p,
                     const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  t.stamps.push_back(TrajectoryTime::from_ns(Duration::from_seconds(stamp_s).ns));
  t.p_world_m.push_back(p);
  t.R_world_body.push_back(R);
}

/// A wavy 3D path sampled at 10 Hz for `seconds`, with turning orientation: nothing in it is
/// collinear or planar, so every alignment is determined.
inline Trajectory wavy_trajectory(const std::string& name, double seconds) {
  Trajectory t;
  t.source = name;
  t.format = TrajectoryFormat::kTum;
  for (int i = 0; i <= static_cast<int>(seconds * 10.0); ++i) {
    const double s = 0.1 * i;
    add_pose(t, 100.0 + s,
             Eigen::Vector3d(3.0 * std::cos(0.3 * s) + s, 2.0 * std::sin(0.5 * s),
                             0.5 * std::sin(0.9 * s)),
             rot(0.1 * std::sin(s), 0.05 * std::cos(0.7 * s), 0.3 * s));
  }
  return t;
}

}  // namespace posed::eval::test
