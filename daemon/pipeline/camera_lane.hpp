#pragma once
// The camera front end's thread (fusion::TaskLane): the fusion core posts its camera work here in
// measurement order and drains the lane where the window step needs the frames, so on a 2-core
// robot the camera front end runs beside the lidar front end instead of after it (issue 18). The
// tasks run one after another in the order posted, so the estimate is the one the fusion thread
// alone would make. Bounded: a post waits for room, so the fusion thread can run at most
// `capacity` tasks ahead.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <thread>

#include "core/fusion/task_lane.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/stage_support.hpp"

namespace posed::pipeline {

struct CameraLaneCounters {
  std::uint64_t tasks = 0;        ///< tasks run [1]
  std::uint64_t full_waits = 0;   ///< posts that waited for room [1]
  std::uint64_t drain_waits = 0;  ///< drains that found work still to do [1]
};

class CameraLane final : public fusion::TaskLane {
 public:
  /// Starts the thread ("posed-camera") under `policy`. `heartbeat` (optional; it must outlive
  /// the lane) beats while the lane waits for work and before and after each task, so a task
  /// that hangs stops it: the watchdog then names the camera front end, not only the fusion
  /// stage that waits for it in drain().
  explicit CameraLane(const config::ThreadSection& policy, std::size_t capacity = 256,
                      Heartbeat* heartbeat = nullptr);
  /// Runs what is still posted, then ends the thread.
  ~CameraLane() override;
  CameraLane(const CameraLane&) = delete;
  CameraLane& operator=(const CameraLane&) = delete;

  void post(Task task) override;
  void drain() override;
  CameraLaneCounters counters() const;

 private:
  void run(config::ThreadSection policy);

  const std::size_t capacity_;
  Heartbeat* const heartbeat_;
  mutable std::mutex mutex_;
  std::condition_variable work_;  // a task was posted, or stopping
  std::condition_variable room_;  // a task was taken
  std::condition_variable idle_;  // nothing posted and nothing running
  std::deque<Task> tasks_;
  bool running_task_ = false;
  bool stopping_ = false;
  CameraLaneCounters counters_;
  std::thread thread_;
};

}  // namespace posed::pipeline
