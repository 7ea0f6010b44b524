#pragma once
// Where the camera front end's work runs. The core hands it tasks in the order the measurements
// came and waits for them only where it needs their result (the window step), so the front end
// can run beside the lidar front end without the core starting a thread (DESIGN.md: threads
// belong to a runner around the core). InlineLane runs each task at once on the caller's thread;
// the daemon's CameraLane (daemon/pipeline/camera_lane.hpp) runs them on a thread of its own.
// Either way the tasks run one after another in the order posted, so the estimate is the same.

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

class InlineLane final : public TaskLane {
 public:
  void post(Task task) override { task(); }
  void drain() override {}
};

}  // namespace posed::fusion
