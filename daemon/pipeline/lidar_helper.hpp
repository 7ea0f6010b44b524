#pragma once
// Helper threads for the lidar front end's per-point work (WorkSplitter, issue 18): the fusion
// thread cuts the scan match's correspondence search into parts and runs them here and on itself
// at once, so on a 2-core robot a scan is matched on both cores. A scan's front end cannot run
// beside the previous scan's back end instead: its prediction and its deskew come from the state
// that back end makes (docs/realtime.md). Every part writes its own output and the fusion thread
// joins them in order, so the estimate is the same with or without helpers, however they are
// scheduled. A part no helper has taken yet when the caller is free is run by the caller, so a
// helper kept from its core by other threads delays nothing.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "core/work_splitter.hpp"
#include "daemon/config/posed_config.hpp"

namespace posed::pipeline {

struct LidarHelperCounters {
  std::uint64_t jobs = 0;          ///< run() calls [1]
  std::uint64_t parts = 0;         ///< parts run [1]
  std::uint64_t helper_parts = 0;  ///< of them, on a helper thread [1]
};

class LidarHelper final : public WorkSplitter {
 public:
  /// Starts `threads` helpers ("posed-lidar-hN") under `policy`.
  LidarHelper(const config::ThreadSection& policy, std::size_t threads);
  ~LidarHelper() override;
  LidarHelper(const LidarHelper&) = delete;
  LidarHelper& operator=(const LidarHelper&) = delete;

  /// One caller at a time (the fusion thread): a job is posted, shared and joined before the next.
  void run(std::size_t parts, const Part& part) override;
  LidarHelperCounters counters() const;

 private:
  void work(config::ThreadSection policy, std::size_t index);
  /// Claims and runs parts of the current job until none is left; returns how many it ran.
  std::size_t run_claimed(const Part& part, std::size_t parts);

  mutable std::mutex mutex_;
  std::condition_variable wake_;  // a job was posted, or stopping
  std::condition_variable done_;  // a helper left the job
  const Part* part_ = nullptr;    // the job; null between jobs
  std::size_t parts_ = 0;
  std::atomic<std::size_t> next_{0};  // the next part to claim
  std::size_t active_ = 0;            // helpers in the job
  std::uint64_t generation_ = 0;      // jobs posted
  bool stopping_ = false;
  LidarHelperCounters counters_;
  std::vector<std::thread> threads_;
};

}  // namespace posed::pipeline
