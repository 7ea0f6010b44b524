#pragma once
// Builds the live Sources the configuration asks for. `posectl replay` builds replay Sources
// instead and passes them to the same Pipeline.

#include <string>

#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/pipeline.hpp"
#include "drivers/synthetic/synthetic_imu_source.hpp"

namespace posed::pipeline {

struct BuiltSources {
  PipelineSources sources;
  /// set when the IMU is the synthetic one, so the summary can compare against its known motion;
  /// owned by `sources`
  const drivers::SyntheticImuSource* synthetic = nullptr;
};

/// The synthetic IMU as the config describes it (also used by tests and the demo).
drivers::SyntheticImuConfig synthetic_imu_config(const config::PosedConfig& config);

/// On failure the returned sources are empty and `error` says why.
BuiltSources make_sources(const config::PosedConfig& config, std::string& error);

}  // namespace posed::pipeline
