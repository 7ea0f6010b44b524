#pragma once
// The simulated rig as a posed configuration describes it (config/posed.yaml: extrinsics, rates,
// IMU noise, intrinsics), so what is simulated is what posed will be configured with.

#include "daemon/config/posed_config.hpp"
#include "tools/sim/simulator.hpp"

namespace posed::sim {

SimRig rig_from_config(const config::PosedConfig& config);

}  // namespace posed::sim
