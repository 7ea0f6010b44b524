#pragma once
// Replay Sources for `posed --replay`: one McapReplaySource per stream found in the recording,
// passed to the same Pipeline as the live Sources. They are not live, so the pipeline's queues
// block instead of dropping and a replay at full speed is deterministic.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/time.hpp"
#include "daemon/pipeline/source_factory.hpp"
#include "drivers/recording/mcap_chunk_cache.hpp"

namespace posed::drivers::recording {
class McapReplaySource;
}

namespace posed::pipeline {

struct ReplayOptions {
  std::string path;
  /// 1 = recorded timing, N = N times faster, 0 = as fast as the pipeline takes it
  double rate = 1.0;
  /// skip this much of the recording [s]
  double start_s = 0;
  /// replay only this much of it; 0 = to the end [s]
  double duration_s = 0;
  /// run pass after pass (run_daemon), each through a pipeline of its own; the Sources made
  /// here replay one pass
  bool loop = false;
  /// with loop: stop after this many passes; 0 = until a signal
  std::uint64_t max_passes = 0;
  /// added to every receive time (a --loop pass after the first starts where the last ended)
  Duration time_shift = Duration::from_ns(0);
  /// at recorded timing, re-stamped onto the host clock now (ReplayTimeline): the replay looks
  /// live to ClockSync, the estimator and DDS subscribers (rate must be 1)
  bool live_stamps = false;
  /// replaying with the configuration the recording was made with (--recorded-config): the lidar
  /// packets are decoded with the calibration recorded beside them, not lidar.calibration's file
  bool recorded_config = false;
  /// replay the D435i's depth stream, if recorded (depth_camera.feature_depth: its only use)
  bool depth = true;
  /// replay only these recorded streams (posed --streams imu,lidar: lidar-inertial alone on a
  /// four-sensor recording, without decoding its images); empty: every stream with a stage. The
  /// IMU must be among them; a stream the recording lacks is an error.
  std::vector<std::string> only_streams;
};

struct ReplaySources {
  BuiltSources built;
  /// the recording's wall-minus-host offset, so replayed poses carry the recorded wall time
  HostToWall host_to_wall{};
  bool have_host_to_wall = false;
  /// streams found, e.g. "imu, lidar"
  std::string streams;
  /// the replay Sources in `built`, to ask what a pass delivered (valid while they live)
  std::vector<const drivers::recording::McapReplaySource*> replayers;
  /// the chunks the streams share (its counters: how often one stream's decompression served
  /// another)
  std::shared_ptr<drivers::recording::McapChunkCache> chunks;
};

/// On failure the sources are empty and `error` names the file and the problem.
ReplaySources make_replay_sources(const ReplayOptions& options, std::string& error);

/// The effective configuration a recording was made with (`posed --record` and `posectl record`
/// write it into every raw channel's metadata as posed.config; the IMU channel's is taken), as
/// YAML the config loader reads. False with `error` naming the file when it has none (an import,
/// a simulation) or cannot be read.
bool read_recorded_config(const std::string& path, std::string& yaml, std::string& error);

}  // namespace posed::pipeline
