#pragma once
// The absolute schedule of a paced replay: message i is due at
//   anchor_host + (log_i - anchor_log) / rate
// on the host monotonic clock, and the sender sleeps until that instant (clock_nanosleep with
// TIMER_ABSTIME). Sleeping "until" rather than "for the gap since the last message" means an
// oversleep or a slow send delays one message, never every message after it: lateness does not
// accumulate over a long replay.

#include <atomic>
#include <cstdint>

#include "core/time.hpp"

namespace posed::hil {

class Pacer {
 public:
  /// `rate`: 1 = recorded timing, 2 = twice as fast; must be > 0.
  explicit Pacer(double rate) : rate_(rate) {}

  /// Log time `log_ns` [ns] is due at host time `host`.
  void anchor(HostTime host, std::int64_t log_ns) {
    anchor_host_ = host;
    anchor_log_ns_ = log_ns;
  }
  /// When a message logged at `log_ns` [ns] is due on the host clock.
  HostTime due(std::int64_t log_ns) const;
  /// Sleeps until `due` (host CLOCK_MONOTONIC), waking at least every 50 ms to look at `stop`.
  /// false when `stop` was set before `due`.
  static bool sleep_until(HostTime due, const std::atomic<bool>& stop);

  double rate() const { return rate_; }
  HostTime anchor_host() const { return anchor_host_; }
  std::int64_t anchor_log_ns() const { return anchor_log_ns_; }

 private:
  double rate_;
  HostTime anchor_host_;
  std::int64_t anchor_log_ns_ = 0;
};

}  // namespace posed::hil
