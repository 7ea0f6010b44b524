#pragma once
// The daemon's main job once the configuration is loaded: open the sources, start the pipeline,
// publish over DDS, talk to systemd, handle signals, and print a summary at the end.

#include <string>

#include "daemon/config/posed_config.hpp"

namespace posed {

struct RunOptions {
  std::string config_path = "/etc/posed/posed.yaml";
  /// stop by itself after this long; 0 = until a signal [s]
  double duration_s = 0;
};

/// Returns the process exit code.
int run_daemon(const config::PosedConfig& config, const RunOptions& options);

}  // namespace posed
