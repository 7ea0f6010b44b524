#pragma once
// The rule behind WatchdogSec= (DESIGN.md, Service): systemd gets WATCHDOG=1 only while every
// pipeline stage has reported within its own deadline. A main loop that pings unconditionally
// would keep a daemon alive whose fusion thread is wedged; tying the ping to per-stage heartbeats
// makes systemd restart posed exactly when the pipeline stops moving.
//
// Time is injected (HostTime, CLOCK_MONOTONIC), never read here, so tests and replays drive it.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/time.hpp"

namespace posed::notify {

/// A stage that has been silent longer than its deadline.
struct StalledStage {
  std::string name;
  Duration silent_for;  ///< now minus its last heartbeat [ns]
  Duration deadline;    ///< how long it may be silent [ns]
};

/// The result of StageWatchdog::check().
struct WatchdogHealth {
  bool healthy = true;  ///< every registered stage beat within its deadline
  std::vector<StalledStage> stalled;

  /// One line for STATUS= and the journal, e.g.
  /// "watchdog withheld: stage fusion silent 2.30 s (deadline 1.00 s)"; "" when healthy.
  std::string describe() const;
};

/// Registry of pipeline stages and their last heartbeats. register_stage() takes a lock (start-up
/// only); heartbeat() is one atomic store, safe from any stage thread at any rate; check() is
/// lock-free too and may run concurrently with both.
class StageWatchdog {
 public:
  using StageId = std::size_t;
  /// Enough for every thread posed runs (sources, sync, fusion, publisher, recorder).
  static constexpr std::size_t kDefaultCapacity = 16;

  /// Slots are preallocated so registering never moves a slot a stage thread is writing.
  explicit StageWatchdog(std::size_t capacity = kDefaultCapacity);
  ~StageWatchdog();
  StageWatchdog(const StageWatchdog&) = delete;
  StageWatchdog& operator=(const StageWatchdog&) = delete;

  /// Adds a stage that counts as having beaten at `now` (so it gets one deadline to start).
  /// Throws std::invalid_argument for a non-positive deadline or when all slots are taken:
  /// both are wiring mistakes found at start-up, never at run time.
  StageId register_stage(std::string name, Duration deadline, HostTime now);

  /// The stage is alive at `now`. One writer per stage (its own thread, or the loop that copies
  /// the pipeline's heartbeats). Returns false for an id that was never registered.
  bool heartbeat(StageId id, HostTime now);

  /// Healthy when every stage's silence (now - last heartbeat) is <= its deadline. With no stage
  /// registered there is nothing to wait for, so that is healthy too.
  WatchdogHealth check(HostTime now) const;

  std::size_t stage_count() const { return count_.load(std::memory_order_acquire); }

 private:
  struct Slot;

  std::unique_ptr<Slot[]> slots_;
  std::size_t capacity_;
  std::atomic<std::size_t> count_{0};
  std::mutex register_mutex_;
};

/// Decides, from the time and the latest check(), what to tell systemd. Pure logic: the caller
/// sends what poll() returns through SdNotifier.
///  - WATCHDOG=1 every WATCHDOG_USEC/2 (systemd's own recommendation), only while healthy; the
///    first healthy poll pings at once, and so does the first healthy poll after a stall.
///  - While a stage stalls, STATUS= names it and how long it has been silent, refreshed every
///    kStallStatusPeriod so `systemctl status` shows the silence growing.
///  - On recovery, STATUS= goes back to the caller's status line.
/// Without a watchdog (nullopt) it never pings but still reports stalls.
class WatchdogPinger {
 public:
  static constexpr Duration kStallStatusPeriod = Duration::from_s(1);

  /// `watchdog_timeout` is WatchdogSec= as SdNotifier::watchdog_interval() reports it.
  explicit WatchdogPinger(std::optional<Duration> watchdog_timeout);

  /// How often WATCHDOG=1 is sent while healthy; nullopt when systemd runs no watchdog.
  std::optional<Duration> ping_period() const { return ping_period_; }

  /// Call often (every main-loop turn, well below ping_period()). Returns the sd_notify message
  /// to send now, if any. `status_line` is what STATUS= should say when all is well.
  std::optional<std::string> poll(HostTime now, const WatchdogHealth& health,
                                  std::string_view status_line);

  /// True from the first unhealthy poll until the next healthy one. While true the caller should
  /// not overwrite STATUS= with its routine status line, or the stall report disappears.
  bool reporting_stall() const { return reporting_stall_; }

 private:
  std::optional<Duration> ping_period_;
  std::optional<HostTime> next_ping_;
  HostTime next_stall_status_;
  bool reporting_stall_ = false;
};

}  // namespace posed::notify
