#pragma once
// DDS stamps are wall time (ROS 2's clock); posed measures on the monotonic clock and converts
// when it stamps (HostToWall, core/time.hpp). A robot's wall clock steps: chrony or
// systemd-timesyncd correcting a real-time clock that was wrong at boot, an operator's `date -s`.
// The monotonic clock never steps. A daemon that read the offset once would, after a step, stamp
// every message off every other node's clock by the step's size, and tf lookups against its poses
// would fail. WallClockFollower re-reads the offset (the daemon's main loop, every 100 ms) and
// adopts it when it moved by kWallClockTolerance or more, so posed's stamps stay on the wall clock
// as every other node's do; moves below that (reading jitter, a slewing NTP between re-reads)
// leave the offset alone, so the stamps of a steady clock never wobble.
//
// Replays stamp with the recording's offset and do not follow; a recording keeps the offset it
// was opened with in its metadata, and its poses at the host times they were made.

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>

#include "core/time.hpp"

namespace posed {

/// Offset moves below this are not steps: stamps stay this close to the wall clock [ns]
inline constexpr Duration kWallClockTolerance = Duration::from_ms(1);

class WallClockFollower {
 public:
  /// `read_wall_minus_host`: wall time minus host monotonic time now.
  explicit WallClockFollower(std::function<Duration()> read_wall_minus_host);
  WallClockFollower(const WallClockFollower&) = delete;
  WallClockFollower& operator=(const WallClockFollower&) = delete;

  /// Re-reads the offset; returns the step when it adopted a new one.
  std::optional<Duration> poll();
  /// Converts with the followed offset; valid while this follower lives.
  HostToWall to_wall() const;
  /// steps adopted since the start [1]
  std::uint64_t steps() const { return steps_; }

 private:
  std::function<Duration()> read_;
  Duration at_start_;
  std::atomic<std::int64_t> wall_minus_host_ns_;
  std::uint64_t steps_ = 0;
};

/// CLOCK_REALTIME minus CLOCK_MONOTONIC now, read between two monotonic readings so a
/// preemption between the reads does not count as a step.
Duration read_wall_minus_host();

}  // namespace posed
