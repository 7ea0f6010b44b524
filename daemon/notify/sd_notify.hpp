#pragma once
// The systemd notification protocol (sd_notify(3)) without libsystemd: one datagram of
// newline-separated KEY=VALUE lines sent to the unix socket named by $NOTIFY_SOCKET. The
// protocol is small and stable, and not linking libsystemd keeps posed buildable and testable on
// machines (and in containers) that have no systemd at all. Outside systemd $NOTIFY_SOCKET is
// absent and every call is a cheap no-op, so the daemon never has to ask "am I a service?".

#include <sys/types.h>

#include <optional>
#include <string>
#include <string_view>

#include "core/time.hpp"

namespace posed::notify {

enum class NotifyStatus {
  kSent,             ///< the datagram went to $NOTIFY_SOCKET
  kNotUnderSystemd,  ///< $NOTIFY_SOCKET is unset: nothing to do, not an error
  kFailed,           ///< the address is invalid or the send failed; see NotifyResult::error
};

struct NotifyResult {
  NotifyStatus status = NotifyStatus::kNotUnderSystemd;
  /// Why it failed, with the socket address and errno text; empty unless kFailed.
  std::string error;

  bool failed() const { return status == NotifyStatus::kFailed; }
};

/// The watchdog timeout systemd expects us to honour, from $WATCHDOG_USEC / $WATCHDOG_PID as
/// sd_watchdog_enabled(3) reads them: nullopt when WATCHDOG_USEC is absent, unparsable or 0, or
/// when WATCHDOG_PID names another process (the variables leaked into a child). This is the full
/// timeout (WatchdogSec=); WatchdogPinger pings at half of it. Pure, for tests.
std::optional<Duration> parse_watchdog_timeout(const char* watchdog_usec, const char* watchdog_pid,
                                               pid_t self_pid);

/// Sends sd_notify messages. Construct once in the main thread; notify() is safe to call from one
/// thread at a time (the daemon's main loop). Non-blocking: a full systemd queue is reported as
/// an error rather than stalling the loop that feeds the watchdog.
class SdNotifier {
 public:
  /// Reads $NOTIFY_SOCKET, $WATCHDOG_USEC and $WATCHDOG_PID once, now.
  SdNotifier();
  /// For tests and for callers that already know the address ("" = not under systemd).
  SdNotifier(std::string socket_address, std::optional<Duration> watchdog_timeout);
  ~SdNotifier();
  SdNotifier(const SdNotifier&) = delete;
  SdNotifier& operator=(const SdNotifier&) = delete;

  /// True when $NOTIFY_SOCKET was set, i.e. systemd is listening.
  bool under_systemd() const { return !address_.empty(); }
  /// The socket address as given ("/run/systemd/notify" or "@abstract-name"); empty if none.
  const std::string& socket_address() const { return address_; }
  /// WatchdogSec= as systemd told us (full timeout, not the ping period); nullopt = no watchdog.
  std::optional<Duration> watchdog_interval() const { return watchdog_timeout_; }

  /// Sends `message` (one or more "KEY=VALUE" lines separated by '\n') as one datagram.
  /// The first failure after a success is also logged as a warning, so an ignored result
  /// still leaves a trace in the journal without flooding it at the loop rate.
  NotifyResult notify(std::string_view message);

 private:
  NotifyResult send(std::string_view message);

  std::string address_;
  std::optional<Duration> watchdog_timeout_;
  int fd_ = -1;
  bool last_failed_ = false;
};

// The messages posed sends (sd_notify(3) names). Building them here keeps the spelling in one
// place and lets tests compare exact bytes.

/// Start-up is complete: sources are open and the pipeline runs.
inline std::string ready_message() { return "READY=1"; }
/// Free-form one-line status shown by `systemctl status posed`.
inline std::string status_message(std::string_view text) { return "STATUS=" + std::string(text); }
/// Keep-alive; send only while every pipeline stage is healthy (StageWatchdog).
inline std::string watchdog_message() { return "WATCHDOG=1"; }
/// Shutdown has begun (drain), so systemd does not take slowness for a hang.
inline std::string stopping_message() { return "STOPPING=1"; }
/// A reload (SIGHUP) has begun. systemd >= 253 (Type=notify-reload) requires MONOTONIC_USEC with
/// it, stamped on CLOCK_MONOTONIC, which is exactly HostTime. READY=1 ends the reload.
std::string reloading_message(HostTime now);
/// CLOCK_MONOTONIC in µs, as systemd expects it.
std::string monotonic_usec_message(HostTime now);
/// The errno of a failure, shown by systemctl status next to STATUS=.
std::string errno_message(int error_number);

}  // namespace posed::notify
