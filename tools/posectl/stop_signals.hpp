#pragma once
// SIGINT and SIGTERM taken synchronously by the main thread of a long posectl command (record,
// replay), as posed does: blocked before any thread starts (threads inherit the mask), then
// waited for with a timeout between progress reports, so the command closes its files cleanly.

#include <signal.h>

#include <ctime>

#include "core/time.hpp"

namespace posed::posectl {

class StopSignals {
 public:
  /// Blocks SIGINT and SIGTERM in this thread and every thread started after.
  StopSignals() {
    sigemptyset(&set_);
    sigaddset(&set_, SIGINT);
    sigaddset(&set_, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &set_, nullptr);
  }

  /// Waits up to `timeout` for SIGINT or SIGTERM: the signal number, or 0 when none came.
  int wait(Duration timeout) {
    const std::int64_t ns = timeout.ns > 0 ? timeout.ns : 0;
    const timespec ts{static_cast<std::time_t>(ns / 1'000'000'000),
                      static_cast<long>(ns % 1'000'000'000)};
    siginfo_t info{};
    const int sig = sigtimedwait(&set_, &info, &ts);
    return sig > 0 ? sig : 0;
  }

 private:
  sigset_t set_{};
};

}  // namespace posed::posectl
