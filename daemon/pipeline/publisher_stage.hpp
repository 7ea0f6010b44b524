#pragma once
// The publisher stage (one thread): hands every state, with the mapping stage's map -> odom for
// it, to the daemon's output callback (DDS, recorder) and, at the status rate, a status snapshot
// with per-stream rates.

#include <Eigen/Geometry>
#include <functional>

#include "core/spsc_queue.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/pipeline_status.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "daemon/pipeline/wakeup.hpp"

namespace posed::pipeline {

class MappingStage;

/// A state in the odometry frame and the map -> odom correction that applies to it (identity
/// without a mapping stage).
using StateCallback = std::function<void(const NavState&, const Eigen::Isometry3d& T_map_odom)>;

class PublisherStage {
 public:
  PublisherStage(const config::PosedConfig& config, SpscQueue<StateItem>& states, Wakeup& ready,
                 Heartbeat& heartbeat, StateCallback on_state,
                 std::function<void(const PipelineStatus&)> on_status,
                 std::function<PipelineStatus()> snapshot, MappingStage* mapping = nullptr);
  /// Runs until end-of-stream arrives; a last status follows it.
  void run();

 private:
  void publish_status();

  const config::PosedConfig& config_;
  SpscQueue<StateItem>& states_;
  Wakeup& ready_;
  Heartbeat& heartbeat_;
  StateCallback on_state_;
  MappingStage* mapping_;
  std::function<void(const PipelineStatus&)> on_status_;
  std::function<PipelineStatus()> snapshot_;
  PipelineStatus previous_;
};

}  // namespace posed::pipeline
