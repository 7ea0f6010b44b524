#include "daemon/pipeline/lidar_helper.hpp"

#include <string>

#include "daemon/pipeline/thread_policy.hpp"

namespace posed::pipeline {

LidarHelper::LidarHelper(const config::ThreadSection& policy, std::size_t threads) {
  threads_.reserve(threads);
  for (std::size_t i = 0; i < threads; ++i) {
    threads_.emplace_back([this, policy, i] { work(policy, i); });
  }
}

LidarHelper::~LidarHelper() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : threads_) t.join();
}

std::size_t LidarHelper::run_claimed(const Part& part, std::size_t parts) {
  std::size_t ran = 0;
  for (std::size_t i = next_.fetch_add(1); i < parts; i = next_.fetch_add(1)) {
    part(i);
    ++ran;
  }
  return ran;
}

void LidarHelper::run(std::size_t parts, const Part& part) {
  if (threads_.empty() || parts < 2) {
    for (std::size_t i = 0; i < parts; ++i) part(i);
    std::lock_guard lock(mutex_);
    ++counters_.jobs;
    counters_.parts += parts;
    return;
  }
  {
    std::lock_guard lock(mutex_);
    part_ = &part;
    parts_ = parts;
    next_.store(0);
    ++generation_;
  }
  wake_.notify_all();
  run_claimed(part, parts);
  // Every part is claimed; wait for the helpers still running theirs.
  std::unique_lock lock(mutex_);
  done_.wait(lock, [&] { return active_ == 0; });
  part_ = nullptr;
  ++counters_.jobs;
  counters_.parts += parts;
}

void LidarHelper::work(config::ThreadSection policy, std::size_t index) {
  apply_thread_policy("posed-lidar-h" + std::to_string(index + 1), policy);
  std::unique_lock lock(mutex_);
  // No job was posted before the helpers were made: one posted before this thread got here is
  // still to be joined, so start from 0, not from generation_.
  std::uint64_t seen = 0;
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || generation_ != seen; });
    if (stopping_) return;
    seen = generation_;
    // A job the caller finished alone before this helper woke is gone (part_ is null).
    if (part_ == nullptr) continue;
    const Part* part = part_;
    const std::size_t parts = parts_;
    ++active_;
    lock.unlock();
    const std::size_t ran = run_claimed(*part, parts);
    lock.lock();
    counters_.helper_parts += ran;
    if (--active_ == 0) done_.notify_all();
  }
}

LidarHelperCounters LidarHelper::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

}  // namespace posed::pipeline
