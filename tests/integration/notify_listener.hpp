#pragma once
// A fake systemd: the unix datagram socket $NOTIFY_SOCKET points at, owned by the test, which
// collects what the daemon sends (READY=1, WATCHDOG=1, STATUS=..., STOPPING=1).

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <string>
#include <vector>

namespace posed::testing {

class NotifyListener {
 public:
  /// Binds an abstract socket (no file to clean up); `env()` is the NOTIFY_SOCKET value.
  explicit NotifyListener(const std::string& abstract_name) : name_(abstract_name) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    addr.sun_path[0] = '\0';
    std::memcpy(addr.sun_path + 1, name_.data(), name_.size());
    ::bind(fd_, reinterpret_cast<sockaddr*>(&addr),
           static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + 1 + name_.size()));
  }
  ~NotifyListener() { ::close(fd_); }

  std::string env() const { return "NOTIFY_SOCKET=@" + name_; }

  struct Message {
    std::chrono::steady_clock::time_point received;
    std::string text;
  };

  /// Collects messages for `duration` (or until one contains `until`, when given).
  std::vector<Message> collect(std::chrono::milliseconds duration, const std::string& until = "") {
    std::vector<Message> out;
    const auto deadline = std::chrono::steady_clock::now() + duration;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) break;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
      char buf[4096];
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) continue;
      out.push_back(
          {std::chrono::steady_clock::now(), std::string(buf, static_cast<std::size_t>(n))});
      if (!until.empty() && out.back().text.find(until) != std::string::npos) break;
    }
    return out;
  }

 private:
  std::string name_;
  int fd_ = -1;
};

}  // namespace posed::testing
