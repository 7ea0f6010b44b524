#pragma once
// rt/posed/odom off the heavy path (DESIGN.md, Data flow): the IMU stage integrates each sample
// it has just synced onto the newest state the back end optimised (core's OdometryPropagator)
// and hands the result to the publisher at once, on its own thread. Scan matching, the camera
// front end and the window never stand between an IMU sample and its odometry.
//
// The back end (the fusion stage) hands its anchors over through a queue, each tagged with the
// newest IMU stamp it had consumed when it made it (`released_at`), and publishes that stamp as
// its progress.
//   live, or a replay at recorded timing: each sample takes whatever anchors have arrived.
//   max-speed replays (`deterministic`): sample k waits until the back end has consumed IMU up to
//     its stamp, then takes exactly the anchors released before it (released_at < stamp), so the
//     odometry is a function of the data alone, however the threads were scheduled; this is
//     what the serial core did, and it costs throughput nothing that matters (the back end is
//     the slower side anyway).

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>

#include "core/estimator/nav_state.hpp"
#include "core/estimator/odometry_propagator.hpp"
#include "core/spsc_queue.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "daemon/pipeline/wakeup.hpp"

namespace posed::pipeline {

/// An anchor from the back end to the odometry.
struct AnchorItem {
  NavState state;
  /// the newest IMU sample stamp the back end had consumed when it produced the state
  HostTime released_at;
};

/// How far the back end has consumed the IMU; written by the fusion stage, read by the IMU stage.
class BackEndProgress {
 public:
  /// After the back end consumed the IMU sample at `t` and queued the anchors it released.
  void consumed_imu(HostTime t) {
    imu_ns_.store(t.ns, std::memory_order_release);
    advanced_.signal();
  }
  /// The back end has ended: nothing more will come.
  void ended() {
    ended_.store(true, std::memory_order_release);
    advanced_.signal();
  }
  bool reached(HostTime t) const {
    return ended_.load(std::memory_order_acquire) ||
           imu_ns_.load(std::memory_order_acquire) >= t.ns;
  }
  bool wait_for(std::chrono::nanoseconds timeout) { return advanced_.wait_for(timeout); }

 private:
  std::atomic<std::int64_t> imu_ns_{std::numeric_limits<std::int64_t>::min()};
  std::atomic<bool> ended_{false};
  Wakeup advanced_;
};

class OdometryPath {
 public:
  /// `on_odom` is called on the IMU stage's thread for every odometry state.
  OdometryPath(const estimator::OdometryPropagatorConfig& config, SpscQueue<AnchorItem>& anchors,
               BackEndProgress& progress, bool deterministic,
               std::function<void(const NavState&)> on_odom);

  /// One synced IMU sample that has already gone to the back end's queue (and the back end was
  /// signalled). `heartbeat` beats while a deterministic replay waits for the back end.
  void on_imu(const ImuSample& sample, HostTime received, Heartbeat& heartbeat);

  const estimator::OdometryFigures& figures() const { return propagator_.figures(); }

 private:
  /// Hands the propagator the anchors this sample may see.
  void take_anchors(HostTime sample_stamp);

  estimator::OdometryPropagator propagator_;
  SpscQueue<AnchorItem>& anchors_;
  BackEndProgress& progress_;
  bool deterministic_;
  std::function<void(const NavState&)> on_odom_;
  std::optional<AnchorItem> next_;  ///< popped, not yet due (deterministic)
};

}  // namespace posed::pipeline
