#pragma once
// The summary a person reads at the end of a run (posed, posectl export): what each stream
// delivered, the estimator's figures, what was published and how late, the recording, the map,
// and the final pose.

#include <string>

#include "core/time.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pose_sinks.hpp"
#include "daemon/run_daemon.hpp"

namespace posed {

namespace pipeline {
class Pipeline;
}
namespace drivers {
class SyntheticImuSource;
}
namespace drivers::recording {
class Recorder;
class McapChunkCache;
}  // namespace drivers::recording

class CloudOutput;
class ImageOutput;
namespace foxglove {
class Server;
}

struct RunSummary {
  const config::PosedConfig& config;
  const RunOptions& options;
  const pipeline::Pipeline& pipe;  ///< joined
  const PoseSinks& sinks;
  HostTime started;           ///< the process's start
  HostTime pipeline_started;  ///< the pipeline's start (the replay's real-time factor)
  std::string replay_streams;
  bool has_lidar = false;
  const drivers::recording::Recorder* recorder = nullptr;  ///< closed; null: not recording
  std::string map_line;                                    ///< "" without --save-map
  const drivers::SyntheticImuSource* synthetic = nullptr;  ///< the truth of a synthetic IMU
  bool published = true;                ///< a DDS participant published (false: an offline run)
  const CloudOutput* clouds = nullptr;  ///< stopped; null: no cloud or map output
  const foxglove::Server* foxglove = nullptr;  ///< null: no Foxglove server
  const ImageOutput* images = nullptr;         ///< stopped; null: no image output
  std::uint64_t passes = 1;    ///< over the recording (--loop); the figures above are the last's
  HostTime last_pass_started;  ///< the last pass's start (its streams' mean rates)
  /// the chunks the last pass's streams shared; null: not a replay
  const drivers::recording::McapChunkCache* replay_chunks = nullptr;
};

/// Prints it to stdout; false when there was no pose at all (the estimator never aligned).
bool print_run_summary(const RunSummary& r);

}  // namespace posed
