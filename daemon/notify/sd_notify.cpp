#include "daemon/notify/sd_notify.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "drivers/common/log.hpp"

namespace posed::notify {
namespace {

/// Parses a whole decimal string; nullopt on anything else (sign, spaces, overflow, empty).
template <class T>
std::optional<T> parse_decimal(const char* text) {
  if (text == nullptr || *text == '\0') return std::nullopt;
  const char* end = text + std::strlen(text);
  T value{};
  const auto [ptr, ec] = std::from_chars(text, end, value);
  if (ec != std::errc{} || ptr != end) return std::nullopt;
  return value;
}

/// Turns "$NOTIFY_SOCKET" into a sockaddr: "/abs/path" is a filesystem socket, "@name" an
/// abstract one (leading NUL, no terminating NUL, the length says where it ends).
bool make_address(const std::string& text, sockaddr_un& addr, socklen_t& length,
                  std::string& error) {
  addr = sockaddr_un{};
  addr.sun_family = AF_UNIX;
  if (text.empty() || (text[0] != '/' && text[0] != '@')) {
    // systemd >= 254 may also pass "vsock:CID:PORT" (VMs); posed runs on the robot's host.
    error = "NOTIFY_SOCKET='" + text + "' is neither an absolute path nor an abstract '@' name";
    return false;
  }
  // A filesystem path needs room for its terminating NUL; an abstract name's '@' becomes the
  // leading NUL, so both fit when text.size() < sizeof sun_path.
  if (text.size() >= sizeof addr.sun_path) {
    error = "NOTIFY_SOCKET='" + text + "' is longer than a unix socket address (" +
            std::to_string(sizeof addr.sun_path - 1) + " bytes)";
    return false;
  }
  std::memcpy(addr.sun_path, text.data(), text.size());
  if (text[0] == '@') addr.sun_path[0] = '\0';
  const std::size_t used = text[0] == '@' ? text.size() : text.size() + 1;
  length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + used);
  return true;
}

std::string errno_text(int error_number) { return std::strerror(error_number); }

}  // namespace

std::optional<Duration> parse_watchdog_timeout(const char* watchdog_usec, const char* watchdog_pid,
                                               pid_t self_pid) {
  // WATCHDOG_PID is set by systemd so a forked child that inherited the environment does not
  // feed the parent's watchdog; when present it must name us.
  if (watchdog_pid != nullptr) {
    const auto pid = parse_decimal<long long>(watchdog_pid);
    if (!pid || *pid != static_cast<long long>(self_pid)) return std::nullopt;
  }
  const auto usec = parse_decimal<std::uint64_t>(watchdog_usec);
  // Cap before converting so an absurd value cannot overflow the ns count (292 years).
  constexpr std::uint64_t kMaxUsec = static_cast<std::uint64_t>(INT64_MAX / 1'000);
  if (!usec || *usec == 0 || *usec > kMaxUsec) return std::nullopt;
  return Duration::from_us(static_cast<std::int64_t>(*usec));
}

SdNotifier::SdNotifier() {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  address_ = socket != nullptr ? socket : "";
  watchdog_timeout_ =
      parse_watchdog_timeout(std::getenv("WATCHDOG_USEC"), std::getenv("WATCHDOG_PID"), ::getpid());
}

SdNotifier::SdNotifier(std::string socket_address, std::optional<Duration> watchdog_timeout)
    : address_(std::move(socket_address)), watchdog_timeout_(watchdog_timeout) {}

SdNotifier::~SdNotifier() {
  if (fd_ >= 0) ::close(fd_);
}

NotifyResult SdNotifier::notify(std::string_view message) {
  NotifyResult result = send(message);
  if (result.failed() && !last_failed_) {
    POSED_LOG_WARN("sd_notify: %s", result.error.c_str());
  }
  if (result.status != NotifyStatus::kNotUnderSystemd) last_failed_ = result.failed();
  return result;
}

NotifyResult SdNotifier::send(std::string_view message) {
  if (address_.empty()) return {NotifyStatus::kNotUnderSystemd, {}};
  if (message.empty()) return {NotifyStatus::kFailed, "empty sd_notify message"};

  sockaddr_un addr{};
  socklen_t length = 0;
  std::string error;
  if (!make_address(address_, addr, length, error)) return {NotifyStatus::kFailed, error};

  if (fd_ < 0) {
    // Non-blocking: if systemd is slow to drain its queue we report it instead of stalling the
    // main loop (which would then miss its own watchdog deadline).
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (fd_ < 0) {
      return {NotifyStatus::kFailed, "cannot create a unix datagram socket for NOTIFY_SOCKET='" +
                                         address_ + "': " + errno_text(errno)};
    }
  }

  ssize_t sent = -1;
  do {
    // MSG_NOSIGNAL: a vanished receiver must not kill us with SIGPIPE.
    sent = ::sendto(fd_, message.data(), message.size(), MSG_NOSIGNAL,
                    reinterpret_cast<const sockaddr*>(&addr), length);
  } while (sent < 0 && errno == EINTR);
  if (sent < 0) {
    return {NotifyStatus::kFailed, "sending '" + std::string(message.substr(0, 40)) +
                                       "' to NOTIFY_SOCKET='" + address_ +
                                       "' failed: " + errno_text(errno)};
  }
  if (static_cast<std::size_t>(sent) != message.size()) {
    return {NotifyStatus::kFailed, "NOTIFY_SOCKET='" + address_ + "' took " + std::to_string(sent) +
                                       " of " + std::to_string(message.size()) + " bytes"};
  }
  return {NotifyStatus::kSent, {}};
}

std::string monotonic_usec_message(HostTime now) {
  return "MONOTONIC_USEC=" + std::to_string(now.ns / 1'000);
}

std::string reloading_message(HostTime now) {
  return "RELOADING=1\n" + monotonic_usec_message(now);
}

std::string errno_message(int error_number) { return "ERRNO=" + std::to_string(error_number); }

}  // namespace posed::notify
