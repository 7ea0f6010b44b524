#pragma once
// The daemon's main job once the configuration is loaded: open the sources, start the pipeline,
// publish over DDS, talk to systemd, handle signals, and print a summary at the end.

#include <string>

#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/replay_sources.hpp"

namespace posed {

struct RunOptions {
  std::string config_path = "/etc/posed/posed.yaml";
  /// stop by itself after this long; 0 = until a signal [s] (live Sources only; a replay's
  /// span is replay.duration_s)
  double duration_s = 0;
  /// record every Source's raw bytes, and the poses, to this MCAP file; empty = no recording
  std::string record_path;
  /// with record_path: the DDS outputs recorded too, as ros2msg channels (parse_record_outputs)
  std::string record_outputs = "tf,tf_static,path,diagnostics,status";
  /// at the end of the run, write the estimator's lidar map here (PCD) and the keyframe poses
  /// next to it (keyframes_path_for()); empty = keep no map
  std::string map_path;
  /// at the end of the run, write the mapping stage's loop-closed keyframe map to this directory
  /// (drivers/recording/map_directory.hpp), which --map loads; empty = none
  std::string map_dir;
  /// localise on the keyframe map in this directory (posed --map DIR); empty = map as you go
  std::string prior_map_dir;
  /// replay this recording instead of opening the sensors (replay.path empty = live)
  pipeline::ReplayOptions replay;
  /// before the first sample, wait up to this long for a DDS reader of odom or pose to match;
  /// negative: 1 s when replaying (a fast replay could end before discovery), 0 live [s]
  double wait_subscribers_s = -1;
  /// false: join no DDS domain and publish nothing (offline jobs such as posectl export --pcd)
  bool publish_dds = true;
};

/// Where the keyframe poses of a map saved to `map_path` go: MAP.pcd -> MAP.keyframes.tum.
std::string keyframes_path_for(const std::string& map_path);
/// Whether --save-map PATH names a keyframe map directory (RunOptions::map_dir) rather than a PCD
/// file (RunOptions::map_path): whether it does not end in .pcd.
bool is_map_directory_path(const std::string& map_path);

/// Returns the process exit code.
int run_daemon(const config::PosedConfig& config, const RunOptions& options);

}  // namespace posed
