#pragma once
// The one place live Sources read the host clock (CLOCK_MONOTONIC), so the stamp a Source
// records is the same clock ClockSync maps onto. Replay Sources never call this.

#include <ctime>

#include "core/time.hpp"

namespace posed::drivers {

inline HostTime host_now() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return HostTime::from_ns(static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec);
}

inline WallTime wall_now() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return WallTime::from_ns(static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec);
}

}  // namespace posed::drivers
