#include "daemon/wall_clock_follower.hpp"

#include <cstdlib>

#include "drivers/common/host_clock.hpp"

namespace posed {

WallClockFollower::WallClockFollower(std::function<Duration()> read_wall_minus_host)
    : read_(std::move(read_wall_minus_host)),
      at_start_(read_()),
      wall_minus_host_ns_(at_start_.ns) {}

std::optional<Duration> WallClockFollower::poll() {
  const Duration now = read_();
  const Duration step{now.ns - wall_minus_host_ns_.load(std::memory_order_relaxed)};
  if (std::llabs(step.ns) < kWallClockTolerance.ns) return std::nullopt;
  wall_minus_host_ns_.store(now.ns, std::memory_order_relaxed);
  ++steps_;
  return step;
}

HostToWall WallClockFollower::to_wall() const {
  return HostToWall{at_start_, &wall_minus_host_ns_};
}

Duration read_wall_minus_host() {
  // The tightest of a few tries brackets the wall reading within microseconds.
  Duration best{0};
  std::int64_t best_bracket_ns = INT64_MAX;
  for (int i = 0; i < 3; ++i) {
    const HostTime before = drivers::host_now();
    const WallTime wall = drivers::wall_now();
    const HostTime after = drivers::host_now();
    const std::int64_t bracket_ns = (after - before).ns;
    if (bracket_ns < best_bracket_ns) {
      best_bracket_ns = bracket_ns;
      best = Duration{wall.ns - (before.ns + bracket_ns / 2)};
    }
  }
  return best;
}

}  // namespace posed
