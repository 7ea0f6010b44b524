#pragma once
// A stand-in for systemd's notification socket: a unix datagram socket the test binds and
// reads, either at a filesystem path or at an abstract '@' name (the two forms systemd uses).

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace posed::notify::testing {

class FakeNotifySocket {
 public:
  enum class Kind { kPath, kAbstract };

  explicit FakeNotifySocket(Kind kind) {
    static std::atomic<int> counter{0};
    const std::string unique =
        std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
    if (kind == Kind::kPath) {
      char dir_template[] = "/tmp/posed-notify-test-XXXXXX";
      if (::mkdtemp(dir_template) == nullptr) fail("mkdtemp");
      dir_ = dir_template;
      address_ = dir_ + "/notify.sock";
    } else {
      address_ = "@posed-notify-test-" + unique;
    }
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) fail("socket");
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::memcpy(addr.sun_path, address_.data(), address_.size());
    if (kind == Kind::kAbstract) addr.sun_path[0] = '\0';
    const std::size_t used = kind == Kind::kAbstract ? address_.size() : address_.size() + 1;
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr),
               static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + used)) != 0) {
      fail("bind " + address_);
    }
  }
  ~FakeNotifySocket() {
    if (fd_ >= 0) ::close(fd_);
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  FakeNotifySocket(const FakeNotifySocket&) = delete;
  FakeNotifySocket& operator=(const FakeNotifySocket&) = delete;

  /// What NOTIFY_SOCKET would say: "/tmp/.../notify.sock" or "@posed-notify-test-...".
  const std::string& address() const { return address_; }

  /// The next datagram, if one is queued. A unix datagram send has enqueued its bytes by the
  /// time sendto() returns, so no waiting is needed and "nothing queued" is a definite answer.
  std::optional<std::string> receive() {
    char buffer[4096];
    const ssize_t n = ::recv(fd_, buffer, sizeof buffer, MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return std::nullopt;
      fail("recv");
    }
    return std::string(buffer, static_cast<std::size_t>(n));
  }

 private:
  [[noreturn]] static void fail(const std::string& what) {
    throw std::runtime_error(what + ": " + std::strerror(errno));
  }

  int fd_ = -1;
  std::string dir_;
  std::string address_;
};

/// Sets (or unsets, with nullptr) an environment variable for one scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = std::string(old);
    if (value != nullptr) {
      ::setenv(name, value, 1);
    } else {
      ::unsetenv(name);
    }
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_.c_str(), old_->c_str(), 1);
    } else {
      ::unsetenv(name_.c_str());
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_;
  std::optional<std::string> old_;
};

}  // namespace posed::notify::testing
