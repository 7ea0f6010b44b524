#include "daemon/notify/stage_watchdog.hpp"

#include <cstdio>
#include <stdexcept>
#include <utility>

#include "daemon/notify/sd_notify.hpp"

namespace posed::notify {

// One cache line per slot: stage threads beat at hundreds of Hz, and neighbouring slots on one
// line would make every beat bounce that line between cores.
struct alignas(64) StageWatchdog::Slot {
  std::string name;   // written once before the slot is published through count_
  Duration deadline;  // likewise
  std::atomic<std::int64_t> last_beat_ns{0};
};

StageWatchdog::StageWatchdog(std::size_t capacity)
    : slots_(std::make_unique<Slot[]>(capacity)), capacity_(capacity) {}

StageWatchdog::~StageWatchdog() = default;

StageWatchdog::StageId StageWatchdog::register_stage(std::string name, Duration deadline,
                                                     HostTime now) {
  if (deadline.ns <= 0) {
    throw std::invalid_argument("watchdog stage '" + name + "': deadline must be positive, got " +
                                std::to_string(deadline.ns) + " ns");
  }
  std::lock_guard lock(register_mutex_);
  const std::size_t id = count_.load(std::memory_order_relaxed);
  if (id >= capacity_) {
    throw std::invalid_argument("watchdog stage '" + name + "': all " + std::to_string(capacity_) +
                                " stage slots are taken");
  }
  Slot& slot = slots_[id];
  slot.name = std::move(name);
  slot.deadline = deadline;
  slot.last_beat_ns.store(now.ns, std::memory_order_relaxed);
  // Release: a reader that sees the new count also sees the slot's name and deadline.
  count_.store(id + 1, std::memory_order_release);
  return id;
}

bool StageWatchdog::heartbeat(StageId id, HostTime now) {
  if (id >= count_.load(std::memory_order_acquire)) return false;
  // Relaxed is enough: the value is the whole message, and check() tolerates seeing a beat late.
  slots_[id].last_beat_ns.store(now.ns, std::memory_order_relaxed);
  return true;
}

WatchdogHealth StageWatchdog::check(HostTime now) const {
  WatchdogHealth health;
  const std::size_t count = count_.load(std::memory_order_acquire);
  for (std::size_t i = 0; i < count; ++i) {
    const Slot& slot = slots_[i];
    const Duration silent_for =
        now - HostTime::from_ns(slot.last_beat_ns.load(std::memory_order_relaxed));
    // A beat stamped after `now` (a stage thread raced the caller's clock read) is negative
    // silence: healthy.
    if (silent_for > slot.deadline) {
      health.healthy = false;
      health.stalled.push_back({slot.name, silent_for, slot.deadline});
    }
  }
  return health;
}

std::string WatchdogHealth::describe() const {
  if (healthy) return {};
  std::string text =
      stalled.size() == 1 ? "watchdog withheld: stage " : "watchdog withheld: stages ";
  for (std::size_t i = 0; i < stalled.size(); ++i) {
    char part[96];
    std::snprintf(part, sizeof part, " silent %.2f s (deadline %.2f s)",
                  stalled[i].silent_for.seconds(), stalled[i].deadline.seconds());
    if (i > 0) text += ", ";
    text += stalled[i].name;
    text += part;
  }
  return text;
}

WatchdogPinger::WatchdogPinger(std::optional<Duration> watchdog_timeout) {
  // sd_watchdog_enabled(3): "send WATCHDOG=1 ... at half the returned interval", so one late
  // main-loop turn never costs a restart.
  if (watchdog_timeout && watchdog_timeout->ns > 0) ping_period_ = *watchdog_timeout / 2;
}

std::optional<std::string> WatchdogPinger::poll(HostTime now, const WatchdogHealth& health,
                                                std::string_view status_line) {
  if (!health.healthy) {
    // Withholding WATCHDOG=1 is the whole point; say why, now and then again as silence grows.
    if (!reporting_stall_ || now >= next_stall_status_) {
      reporting_stall_ = true;
      next_stall_status_ = now + kStallStatusPeriod;
      return status_message(health.describe());
    }
    return std::nullopt;
  }

  // Recovery: healthy now, so ping at once rather than leave systemd waiting out the stall.
  if (reporting_stall_) next_ping_.reset();
  std::string message;
  if (ping_period_ && (!next_ping_ || now >= *next_ping_)) {
    message = watchdog_message();
    next_ping_ = now + *ping_period_;
  }
  if (reporting_stall_) {
    reporting_stall_ = false;
    if (!message.empty()) message += '\n';
    message += status_message(status_line.empty() ? "all stages healthy again" : status_line);
  }
  if (message.empty()) return std::nullopt;
  return message;
}

}  // namespace posed::notify
