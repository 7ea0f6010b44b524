#include "tools/hil/pty_emitter.hpp"

#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include "drivers/common/host_clock.hpp"

namespace posed::hil {

PtyEmitter::~PtyEmitter() { close(); }

void PtyEmitter::close() {
  if (linked_) {
    // Only our own link: another replay may have taken the path over since.
    std::array<char, 512> target{};
    const ssize_t n = ::readlink(link_path_.c_str(), target.data(), target.size() - 1);
    if (n > 0 && slave_path_ == std::string(target.data(), static_cast<std::size_t>(n))) {
      ::unlink(link_path_.c_str());
    }
    linked_ = false;
  }
  if (master_ >= 0) ::close(master_);
  master_ = -1;
}

bool PtyEmitter::open(std::string& error) {
  const std::string where = "pty " + (link_path_.empty() ? std::string("(no link)") : link_path_);
  auto fail = [&](const char* what) {
    error = where + ": " + what + ": " + std::strerror(errno);
    return false;
  };
  master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (master_ < 0) return fail("posix_openpt");
  if (::grantpt(master_) != 0) return fail("grantpt");
  if (::unlockpt(master_) != 0) return fail("unlockpt");
  std::array<char, 128> name{};
  if (::ptsname_r(master_, name.data(), name.size()) != 0) return fail("ptsname_r");
  slave_path_ = name.data();

  // Raw mode lives in the slave's termios, which outlives this open/close as long as the master
  // is open. Opening and closing the slave once also arms POLLHUP on the master, which from now
  // on says whether any reader has the slave open.
  const int slave = ::open(slave_path_.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave < 0) return fail(("open " + slave_path_).c_str());
  termios tio{};
  if (::tcgetattr(slave, &tio) != 0) {
    ::close(slave);
    return fail("tcgetattr");
  }
  ::cfmakeraw(&tio);
  // The A9's line rate, so `stty -F LINK` shows what the device would; a pty ignores it.
  ::cfsetspeed(&tio, B921600);
  if (::tcsetattr(slave, TCSANOW, &tio) != 0) {
    ::close(slave);
    return fail("tcsetattr");
  }
  ::close(slave);

  if (!link_path_.empty()) {
    struct stat st {};
    if (::lstat(link_path_.c_str(), &st) == 0 && !S_ISLNK(st.st_mode)) {
      error = where + ": exists and is not a symlink; refusing to replace it";
      return false;
    }
    // Atomic replacement, as udev moves a /dev/serial/by-id link: a reader never sees no link.
    const std::string tmp = link_path_ + ".posectl-new";
    ::unlink(tmp.c_str());
    if (::symlink(slave_path_.c_str(), tmp.c_str()) != 0) return fail("symlink");
    if (::rename(tmp.c_str(), link_path_.c_str()) != 0) {
      ::unlink(tmp.c_str());
      return fail("rename");
    }
    linked_ = true;
  }
  return true;
}

void PtyEmitter::drain_reader_output() {
  std::array<char, 512> sink{};
  for (;;) {
    const ssize_t n = ::read(master_, sink.data(), sink.size());
    if (n <= 0) return;
    from_reader_.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
  }
}

bool PtyEmitter::has_reader() {
  if (master_ < 0) return false;
  pollfd p{master_, POLLIN, 0};
  if (::poll(&p, 1, 0) < 0) return false;
  if ((p.revents & POLLHUP) != 0) return false;
  // A reader that writes (commands to the device) would eventually block on a full buffer.
  if ((p.revents & POLLIN) != 0) drain_reader_output();
  return true;
}

bool PtyEmitter::wait_for_reader(Duration timeout, const std::atomic<bool>& stop) {
  const HostTime give_up = drivers::host_now() + timeout;
  while (!has_reader()) {
    if (stop.load(std::memory_order_relaxed) || drivers::host_now() >= give_up) return false;
    // POLLHUP cannot be waited for in reverse, so look again shortly.
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

bool PtyEmitter::write(std::span<const std::byte> bytes) {
  if (!has_reader()) {
    no_reader_.fetch_add(bytes.size(), std::memory_order_relaxed);
    return false;
  }
  while (!bytes.empty()) {
    const ssize_t n = ::write(master_, bytes.data(), bytes.size());
    if (n > 0) {
      bytes_.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
      bytes = bytes.subspan(static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    // EAGAIN: the reader leaves the buffer full, as a UART's FIFO overruns. EIO: it just closed.
    auto& counter = (n < 0 && errno == EAGAIN) ? overrun_ : no_reader_;
    counter.fetch_add(bytes.size(), std::memory_order_relaxed);
    return false;
  }
  writes_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

PtyCounters PtyEmitter::counters() const {
  return {writes_.load(std::memory_order_relaxed), bytes_.load(std::memory_order_relaxed),
          no_reader_.load(std::memory_order_relaxed), overrun_.load(std::memory_order_relaxed),
          from_reader_.load(std::memory_order_relaxed)};
}

}  // namespace posed::hil
