#pragma once
// Wakes a consumer thread when its queue has new items, without it spinning. The producer
// signals after each push; the consumer waits with a timeout so it still heartbeats and sees a
// stop request when nothing arrives.

#include <chrono>
#include <semaphore>

namespace posed::pipeline {

class Wakeup {
 public:
  void signal() { sem_.release(); }
  /// true when signalled, false on timeout
  bool wait_for(std::chrono::nanoseconds timeout) { return sem_.try_acquire_for(timeout); }

 private:
  // A large max so bursts never overflow; the consumer drains its queue on every wake-up anyway.
  std::counting_semaphore<1 << 30> sem_{0};
};

}  // namespace posed::pipeline
