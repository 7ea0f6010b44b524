#include "tools/hil/pacer.hpp"

#include <cerrno>
#include <cmath>
#include <ctime>

#include "drivers/common/host_clock.hpp"

namespace posed::hil {

HostTime Pacer::due(std::int64_t log_ns) const {
  const std::int64_t since_anchor_ns = log_ns - anchor_log_ns_;
  // Integer arithmetic at the recorded rate: no rounding drift over hours of replay.
  if (rate_ == 1.0) return anchor_host_ + Duration::from_ns(since_anchor_ns);
  return anchor_host_ +
         Duration::from_ns(std::llround(static_cast<double>(since_anchor_ns) / rate_));
}

bool Pacer::sleep_until(HostTime due, const std::atomic<bool>& stop) {
  constexpr std::int64_t kSliceNs = 50'000'000;
  for (;;) {
    if (stop.load(std::memory_order_relaxed)) return false;
    const HostTime now = drivers::host_now();
    if (now >= due) return true;
    const std::int64_t wake_ns = (due - now).ns > kSliceNs ? now.ns + kSliceNs : due.ns;
    const timespec at{static_cast<std::time_t>(wake_ns / 1'000'000'000),
                      static_cast<long>(wake_ns % 1'000'000'000)};
    // EINTR only shortens the sleep; the loop looks at the clock again.
    ::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr);
  }
}

}  // namespace posed::hil
