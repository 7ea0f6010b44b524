#pragma once
// Where the camera front end's work runs. The core hands it tasks in the order the measurements
// came and waits for them only where it needs their result (the window step), so the front end
// can run beside the lidar front end without the core starting a thread (DESIGN.md: threads
// belong to a runner around the core). The daemon's CameraLane (daemon/pipeline/camera_lane.hpp)
// runs them on a thread of its own; without a lane the core calls the front end itself. Either
// way the calls run one after another in measurement order, so the estimate is the same.

#include <functional>

namespace posed::fusion {

class TaskLane {
 public:
  using Task = std::function<void()>;
  virtual ~TaskLane() = default;
  /// Runs `task` after every task posted before it.
  virtual void post(Task task) = 0;
  /// Returns once every task posted so far has run; what they wrote is then visible to the
  /// caller.
  virtual void drain() = 0;
};

}  // namespace posed::fusion
