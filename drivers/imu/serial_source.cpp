#include "drivers/imu/serial_source.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"

namespace posed::drivers {

bool baud_to_speed(int baud, unsigned& speed) {
  static constexpr std::pair<int, speed_t> kRates[] = {
      {9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},
      {115200, B115200},   {230400, B230400},   {460800, B460800},   {500000, B500000},
      {576000, B576000},   {921600, B921600},   {1000000, B1000000}, {1152000, B1152000},
      {1500000, B1500000}, {2000000, B2000000}, {3000000, B3000000}, {4000000, B4000000},
  };
  for (const auto& [rate, constant] : kRates) {
    if (rate == baud) {
      speed = constant;
      return true;
    }
  }
  return false;
}

SerialSource::SerialSource(SerialConfig config)
    : config_(std::move(config)), backoff_(config_.reopen_backoff_min) {
  stop_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
}

SerialSource::~SerialSource() {
  close_device();
  if (stop_fd_ >= 0) ::close(stop_fd_);
}

bool SerialSource::open(std::string& error) {
  if (fd_ >= 0) return true;
  if (stop_fd_ < 0) {
    error = "serial " + config_.path + ": eventfd: " + std::strerror(errno);
    return false;
  }
  if (!open_device(error)) return false;
  ever_opened_ = true;
  return true;
}

bool SerialSource::open_device(std::string& error) {
  unsigned speed = 0;
  if (!baud_to_speed(config_.baud, speed)) {
    error = "serial " + config_.path + ": unsupported baud rate " + std::to_string(config_.baud);
    return false;
  }
  // O_NONBLOCK: open must not wait for carrier detect; reads are gated by poll() anyway.
  const int fd = ::open(config_.path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    error = "serial " + config_.path + ": open: " + std::strerror(errno);
    return false;
  }
  auto fail = [&](const char* what) {
    error = "serial " + config_.path + ": " + what + ": " + std::strerror(errno);
    ::close(fd);
    return false;
  };
  if (!::isatty(fd)) return fail("not a tty");
  // Two readers on one serial port each get half the bytes and neither can decode: refuse.
  if (config_.exclusive && ::ioctl(fd, TIOCEXCL) != 0) return fail("TIOCEXCL");
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) return fail("tcgetattr");
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS | CSTOPB);
  // VMIN=0/VTIME=0: read() returns what is there; waiting is poll()'s job, with our timeout.
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  if (::cfsetispeed(&tio, speed) != 0 || ::cfsetospeed(&tio, speed) != 0) {
    return fail("cfsetspeed");
  }
  if (::tcsetattr(fd, TCSANOW, &tio) != 0) return fail("tcsetattr");
  // Bytes queued before we configured the port may be mangled by the old line settings.
  ::tcflush(fd, TCIFLUSH);
  fd_ = fd;
  return true;
}

void SerialSource::close_device() {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

void SerialSource::mark_lost(const char* why, int err) {
  close_device();
  lost_ = true;
  backoff_ = config_.reopen_backoff_min;
  next_reopen_ = host_now() + backoff_;
  reopen_attempts_ = 0;
  POSED_LOG_WARN("%s: serial device %s lost (%s%s%s); reopening with back-off",
                 config_.name.c_str(), config_.path.c_str(), why, err != 0 ? ": " : "",
                 err != 0 ? std::strerror(err) : "");
}

ReadStatus SerialSource::read(RawChunk& chunk, Duration timeout) {
  if (stop_requested_.load(std::memory_order_acquire)) return ReadStatus::kEndOfStream;
  const HostTime deadline = host_now() + timeout;

  if (fd_ < 0) {
    if (!ever_opened_) {
      // Never opened (caller skipped open(), or it failed): try once, then fall into the same
      // back-off as a lost device so a missing port logs one line, not one per read.
      std::string error;
      if (!open(error)) {
        POSED_LOG_WARN("%s: %s; retrying with back-off", config_.name.c_str(), error.c_str());
        ever_opened_ = true;
        lost_ = true;
        backoff_ = config_.reopen_backoff_min;
        next_reopen_ = host_now() + backoff_;
        return ReadStatus::kDeviceLost;
      }
    } else {
      // Lost: wait (interruptibly) for the next reopen slot, but never past the deadline.
      const HostTime wake = std::min(next_reopen_, deadline);
      const Duration wait = wake - host_now();
      if (wait.ns > 0) {
        pollfd pfd{stop_fd_, POLLIN, 0};
        ::poll(&pfd, 1, static_cast<int>((wait.ns + 999'999) / 1'000'000));
        if (stop_requested_.load(std::memory_order_acquire)) return ReadStatus::kEndOfStream;
      }
      if (host_now() < next_reopen_) return ReadStatus::kDeviceLost;
      std::string error;
      if (!open_device(error)) {
        ++reopen_attempts_;
        backoff_ = std::min(backoff_ * 2, config_.reopen_backoff_max);
        next_reopen_ = host_now() + backoff_;
        POSED_LOG_DEBUG("%s: reopen attempt %u failed: %s", config_.name.c_str(), reopen_attempts_,
                        error.c_str());
        return ReadStatus::kDeviceLost;
      }
      lost_ = false;
      counts_.reopened.fetch_add(1, std::memory_order_relaxed);
      POSED_LOG_NOTICE("%s: serial device %s back after %u failed attempt(s)", config_.name.c_str(),
                       config_.path.c_str(), reopen_attempts_);
    }
  }

  for (;;) {
    const Duration left = deadline - host_now();
    pollfd pfds[2] = {{fd_, POLLIN, 0}, {stop_fd_, POLLIN, 0}};
    const int ms = left.ns <= 0 ? 0 : static_cast<int>((left.ns + 999'999) / 1'000'000);
    const int n = ::poll(pfds, 2, ms);
    if (stop_requested_.load(std::memory_order_acquire)) return ReadStatus::kEndOfStream;
    if (n < 0) {
      if (errno == EINTR) continue;
      mark_lost("poll", errno);
      return ReadStatus::kDeviceLost;
    }
    if (n == 0) return ReadStatus::kTimeout;
    if ((pfds[0].revents & POLLNVAL) != 0) {
      mark_lost("invalid descriptor", 0);
      return ReadStatus::kDeviceLost;
    }
    // Drain data before honouring a hang-up: bytes that arrived before the unplug are valid.
    const ssize_t got = ::read(fd_, buffer_.data(), buffer_.size());
    const HostTime received = host_now();
    if (got > 0) {
      chunk.bytes = std::span<const std::byte>(buffer_.data(), static_cast<std::size_t>(got));
      chunk.host_receive = received;
      chunk.channel = 0;
      counts_.count_chunk(static_cast<std::uint64_t>(got));
      return ReadStatus::kData;
    }
    if (got < 0 && (errno == EAGAIN || errno == EINTR)) {
      if (deadline <= host_now()) return ReadStatus::kTimeout;
      continue;
    }
    // EIO/ENXIO/ENODEV on read, or EOF with a hang-up: the USB adapter went away.
    if (got < 0 || (pfds[0].revents & (POLLHUP | POLLERR)) != 0) {
      mark_lost(got < 0 ? "read" : "hang-up", got < 0 ? errno : 0);
      return ReadStatus::kDeviceLost;
    }
    if (deadline <= host_now()) return ReadStatus::kTimeout;
  }
}

void SerialSource::request_stop() {
  stop_requested_.store(true, std::memory_order_release);
  if (stop_fd_ >= 0) {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t w = ::write(stop_fd_, &one, sizeof one);
  }
}

SourceCounters SerialSource::counters() const { return counts_.snapshot(); }

}  // namespace posed::drivers
