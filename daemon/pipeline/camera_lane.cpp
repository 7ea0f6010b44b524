#include "daemon/pipeline/camera_lane.hpp"

#include <utility>

#include "daemon/pipeline/thread_policy.hpp"

namespace posed::pipeline {

CameraLane::CameraLane(const config::ThreadSection& policy, std::size_t capacity,
                       Heartbeat* heartbeat)
    : capacity_(capacity > 0 ? capacity : 1),
      heartbeat_(heartbeat),
      thread_([this, policy] { run(policy); }) {}

CameraLane::~CameraLane() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  work_.notify_all();
  thread_.join();
}

void CameraLane::post(Task task) {
  std::unique_lock lock(mutex_);
  if (tasks_.size() >= capacity_) {
    ++counters_.full_waits;
    room_.wait(lock, [&] { return tasks_.size() < capacity_; });
  }
  tasks_.push_back(std::move(task));
  lock.unlock();
  work_.notify_one();
}

void CameraLane::drain() {
  std::unique_lock lock(mutex_);
  if (tasks_.empty() && !running_task_) return;
  ++counters_.drain_waits;
  idle_.wait(lock, [&] { return tasks_.empty() && !running_task_; });
}

CameraLaneCounters CameraLane::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

void CameraLane::run(config::ThreadSection policy) {
  apply_thread_policy("posed-camera", policy);
  std::unique_lock lock(mutex_);
  const auto beat = [this] {
    if (heartbeat_ != nullptr) heartbeat_->beat();
  };
  for (;;) {
    beat();
    if (!work_.wait_for(lock, kStageWaitTimeout, [&] { return !tasks_.empty() || stopping_; })) {
      continue;  // idle: beat again
    }
    if (tasks_.empty()) break;  // stopping, and everything posted has run
    Task task = std::move(tasks_.front());
    tasks_.pop_front();
    running_task_ = true;
    lock.unlock();
    room_.notify_one();
    task();
    task = nullptr;  // what it held (an image's pool buffer) goes back now, not at the next task
    beat();
    lock.lock();
    running_task_ = false;
    ++counters_.tasks;
    if (tasks_.empty()) idle_.notify_all();
  }
}

}  // namespace posed::pipeline
