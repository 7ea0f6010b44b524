#pragma once
// A trajectory as read from a file: poses T_world_body in the file's own world frame, with
// stamps on the file's own clock (TUM) or none at all (KITTI: pose i belongs to frame i).

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "core/time.hpp"

namespace posed::eval {

/// Whatever clock a trajectory file's stamps use (ROS time, sensor time ...). Only differences
/// between two files' stamps are meaningful, after the user's --offset.
struct TrajectoryClock {};
using TrajectoryTime = TimePoint<TrajectoryClock>;

enum class TrajectoryFormat {
  kAuto,   ///< decided per file from the number of fields on the first pose line
  kTum,    ///< `stamp x y z qx qy qz qw` [s, m, 1]
  kKitti,  ///< 3x4 row-major [R|t] per line, no stamps [1, m]
};

/// "tum", "kitti", "auto"
const char* to_string(TrajectoryFormat format);

struct Trajectory {
  /// the file it came from, for messages
  std::string source;
  /// kTum or kKitti, never kAuto
  TrajectoryFormat format = TrajectoryFormat::kTum;
  /// stamps of the poses, strictly increasing; empty for KITTI [ns]
  std::vector<TrajectoryTime> stamps;
  /// body origin in the world frame of the file [m]
  std::vector<Eigen::Vector3d> p_world_m;
  /// rotation body -> world as the file gives it (KITTI matrices are used as written, like evo
  /// does, not re-orthonormalised) [1]
  std::vector<Eigen::Matrix3d> R_world_body;
  /// false when the file carries positions only (TUM lines with an all-zero quaternion, as
  /// M2DGR's ground truth has): translation errors work, rotation-dependent ones do not
  bool has_orientation = true;

  std::size_t size() const { return p_world_m.size(); }
  bool has_stamps() const { return !stamps.empty(); }
};

}  // namespace posed::eval
