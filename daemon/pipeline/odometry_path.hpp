#pragma once
// rt/posed/odom off the heavy path (DESIGN.md, Data flow): the IMU stage integrates each sample
// it has just synced onto the newest state the back end optimised (core's OdometryPropagator)
// and hands the result to the publisher at once, on its own thread. Scan matching, the camera
// front end and the window never stand between an IMU sample and its odometry.
//
// The back end (the fusion stage) hands its anchors over through a queue; each sample takes
// whatever anchors have arrived. That depends on the threads' timing, which is right live (the
// newest state there is) but would make a max-speed replay's odometry differ from run to run:
// there the fusion stage runs the same propagator itself, in data order (fusion_stage.hpp), where
// latency means nothing anyway.

#include <functional>
#include <mutex>

#include "core/estimator/nav_state.hpp"
#include "core/estimator/odometry_propagator.hpp"
#include "core/spsc_queue.hpp"

namespace posed::pipeline {

/// An anchor from the back end to the odometry.
struct AnchorItem {
  NavState state;
};

class OdometryPath {
 public:
  /// `on_odom` is called on the IMU stage's thread for every odometry state.
  OdometryPath(const estimator::OdometryPropagatorConfig& config, SpscQueue<AnchorItem>& anchors,
               std::function<void(const NavState&)> on_odom);

  /// One synced IMU sample (already on its way to the back end), received at `received`. From
  /// the A9's stage, and from the D435i IMU's while it stands in for a silent A9
  /// (imu_failover.hpp): a sample not newer than the last one propagated is skipped (the two
  /// overlap at a hand-over).
  void on_imu(const ImuSample& sample, HostTime received);

  const estimator::OdometryFigures& figures() const { return propagator_.figures(); }

 private:
  /// the two IMU stages' threads meet here only at a failover; uncontended otherwise
  std::mutex mutex_;
  bool have_last_ = false;
  HostTime last_stamp_;
  estimator::OdometryPropagator propagator_;
  SpscQueue<AnchorItem>& anchors_;
  std::function<void(const NavState&)> on_odom_;
};

}  // namespace posed::pipeline
