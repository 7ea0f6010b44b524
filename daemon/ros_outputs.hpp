#pragma once
// What ROS 2 tools expect next to posed's own topics, built from its states and status (pure
// functions; PoseSinks publishes them): the tf tree (rt/tf, rt/tf_static), the path
// (rt/posed/path) and per-component health (rt/diagnostics).

#include <cstdint>
#include <vector>

#include "core/estimator/nav_state.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/dds/messages.hpp"
#include "daemon/pipeline/pipeline_status.hpp"

namespace posed {

/// base_link -> lidar, colour camera and thermal camera frames from the configured extrinsics.
dds::TfMessage static_transforms(const config::PosedConfig& config, WallTime stamp);

/// map -> odom (`T_map_odom`, the mapping stage's correction) -> base_link (`s`, in odom).
dds::TfMessage tf_tree(const config::DdsSection& dds, const NavState& s,
                       const Eigen::Isometry3d& T_map_odom, WallTime stamp);

/// rt/diagnostics: one status per input stream ("posed: imu", ...) and one for the estimator,
/// levels as diagnostic_msgs defines them.
dds::DiagnosticsMessage diagnostics(const pipeline::PipelineStatus& st, WallTime stamp);

/// The trajectory for rt/posed/path: poses kept at least `min_step_m` apart, and always ending at
/// the newest; past `max_poses`, every other old pose is dropped, so the whole run stays in the
/// path at a coarser spacing and the message size stays bounded.
class PathBuilder {
 public:
  PathBuilder(double min_step_m, std::size_t max_poses)
      : min_step_m_(min_step_m), max_poses_(max_poses) {}
  void add(const dds::PoseMessage& pose);
  const dds::PathMessage& path() const { return path_; }
  /// A new trajectory begins (the next --loop pass): the path starts empty again.
  void clear() { path_.poses.clear(); }

 private:
  double min_step_m_;
  std::size_t max_poses_;
  dds::PathMessage path_;
};

}  // namespace posed
