#pragma once
// A fake A9 on a pseudo-terminal: the test writes to the master, the Source under test opens the
// slave through a symlink (like /dev/serial/by-id/...), so "unplugging" is closing the master and
// "replugging" is a new pty with the symlink moved to it.

#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <system_error>

namespace posed::test {

class FakeA9Pty {
 public:
  /// `link` is the stable path the Source opens (created/replaced here).
  explicit FakeA9Pty(std::filesystem::path link) : link_(std::move(link)) { plug(); }
  ~FakeA9Pty() { unplug(); }
  FakeA9Pty(const FakeA9Pty&) = delete;
  FakeA9Pty& operator=(const FakeA9Pty&) = delete;

  /// Creates a new pty (raw, so the line discipline neither echoes nor translates bytes) and
  /// points the link at its slave. Returns false with `errno` set on failure.
  bool plug() {
    termios raw{};
    ::cfmakeraw(&raw);
    char name[256] = {};
    if (::openpty(&master_, &slave_, name, &raw, nullptr) != 0) return false;
    slave_path_ = name;
    const auto tmp = link_.string() + ".new";
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    std::filesystem::create_symlink(slave_path_, tmp, ec);
    if (ec) return false;
    std::filesystem::rename(tmp, link_, ec);  // atomic, like udev replacing a by-id link
    return !ec;
  }

  /// Closes both ends: the Source's slave sees a hang-up, as on a USB unplug.
  void unplug() {
    if (slave_ >= 0) ::close(slave_);
    if (master_ >= 0) ::close(master_);
    slave_ = master_ = -1;
  }

  /// Our own slave fd only keeps the pty alive until the Source has it open.
  void release_slave() {
    if (slave_ >= 0) ::close(slave_);
    slave_ = -1;
  }

  bool write_all(std::span<const std::uint8_t> bytes) {
    while (!bytes.empty()) {
      const ssize_t n = ::write(master_, bytes.data(), bytes.size());
      if (n <= 0) return false;
      bytes = bytes.subspan(static_cast<std::size_t>(n));
    }
    return true;
  }

  const std::string& slave_path() const { return slave_path_; }

 private:
  std::filesystem::path link_;
  std::string slave_path_;
  int master_ = -1;
  int slave_ = -1;
};

}  // namespace posed::test
