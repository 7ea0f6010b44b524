#include "drivers/imu/socketcan_source.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"

namespace posed::drivers::can {

SocketCanSource::SocketCanSource(SocketCanConfig config)
    : config_(std::move(config)), backoff_(config_.reopen_backoff_min) {
  stop_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
}

SocketCanSource::~SocketCanSource() {
  close_socket();
  if (stop_fd_ >= 0) ::close(stop_fd_);
}

bool SocketCanSource::open(std::string& error) {
  if (fd_ >= 0) return true;
  if (!open_socket(error)) return false;
  ever_opened_ = true;
  return true;
}

bool SocketCanSource::open_socket(std::string& error) {
  const std::string where = "SocketCAN " + config_.interface + ": ";
  if (config_.interface.empty() || config_.interface.size() >= IFNAMSIZ) {
    error = where + "bad interface name";
    return false;
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC | SOCK_NONBLOCK, CAN_RAW);
  if (fd < 0) {
    error = where + "socket(PF_CAN): " + std::strerror(errno);
    return false;
  }
  auto fail = [&](const char* what) {
    error = where + what + ": " + std::strerror(errno);
    ::close(fd);
    return false;
  };
  const int on = 1;
  if (config_.fd_frames && ::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) != 0) {
    return fail("CAN_RAW_FD_FRAMES");
  }
  if (!config_.filters.empty()) {
    std::vector<can_filter> filters;
    for (const auto& f : config_.filters) filters.push_back(can_filter{f.id, f.mask});
    if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                     static_cast<socklen_t>(filters.size() * sizeof(can_filter))) != 0) {
      return fail("CAN_RAW_FILTER");
    }
  }
  // Error frames tell us about bus-off and controller trouble; without this the kernel drops them.
  const can_err_mask_t err_mask = CAN_ERR_MASK;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) != 0) {
    return fail("CAN_RAW_ERR_FILTER");
  }
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, config_.interface.c_str(), config_.interface.size() + 1);
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) != 0) return fail("SIOCGIFINDEX");
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) return fail("bind");
  fd_ = fd;
  return true;
}

void SocketCanSource::close_socket() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void SocketCanSource::mark_lost(const char* why, int err) {
  close_socket();
  backoff_ = config_.reopen_backoff_min;
  next_reopen_ = host_now() + backoff_;
  POSED_LOG_WARN("%s: CAN interface %s lost (%s%s%s); reopening with back-off",
                 config_.name.c_str(), config_.interface.c_str(), why, err != 0 ? ": " : "",
                 err != 0 ? std::strerror(err) : "");
}

ReadStatus SocketCanSource::read(RawChunk& chunk, Duration timeout) {
  if (stop_requested_.load(std::memory_order_acquire)) return ReadStatus::kEndOfStream;
  const HostTime deadline = host_now() + timeout;
  if (fd_ < 0) {
    if (!ever_opened_) {
      std::string error;
      if (!open(error)) {
        POSED_LOG_WARN("%s: %s; retrying with back-off", config_.name.c_str(), error.c_str());
        ever_opened_ = true;
        next_reopen_ = host_now() + backoff_;
        return ReadStatus::kDeviceLost;
      }
    } else {
      const Duration wait = std::min(next_reopen_, deadline) - host_now();
      if (wait.ns > 0) {
        pollfd pfd{stop_fd_, POLLIN, 0};
        ::poll(&pfd, 1, static_cast<int>((wait.ns + 999'999) / 1'000'000));
        if (stop_requested_.load(std::memory_order_acquire)) return ReadStatus::kEndOfStream;
      }
      if (host_now() < next_reopen_) return ReadStatus::kDeviceLost;
      std::string error;
      if (!open_socket(error)) {
        backoff_ = std::min(backoff_ * 2, config_.reopen_backoff_max);
        next_reopen_ = host_now() + backoff_;
        return ReadStatus::kDeviceLost;
      }
      counts_.reopened.fetch_add(1, std::memory_order_relaxed);
      POSED_LOG_NOTICE("%s: CAN interface %s back", config_.name.c_str(),
                       config_.interface.c_str());
    }
  }
  for (;;) {
    const Duration left = deadline - host_now();
    pollfd pfds[2] = {{fd_, POLLIN, 0}, {stop_fd_, POLLIN, 0}};
    const int n =
        ::poll(pfds, 2, left.ns <= 0 ? 0 : static_cast<int>((left.ns + 999'999) / 1'000'000));
    if (stop_requested_.load(std::memory_order_acquire)) return ReadStatus::kEndOfStream;
    if (n < 0 && errno == EINTR) continue;
    if (n == 0) return ReadStatus::kTimeout;
    const ssize_t got = n < 0 ? -1 : ::read(fd_, buffer_.data(), buffer_.size());
    const HostTime received = host_now();
    if (got < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      mark_lost("read", errno);  // ENETDOWN when the interface goes down
      return ReadStatus::kDeviceLost;
    }
    const auto size = static_cast<std::size_t>(got);
    if (size != kCanMtu && size != kCanFdMtu) continue;  // not a frame: cannot happen on CAN_RAW
    canid_t id = 0;
    std::memcpy(&id, buffer_.data(), sizeof id);
    if ((id & CAN_ERR_FLAG) != 0) {
      error_frames_.fetch_add(1, std::memory_order_relaxed);
      if ((id & CAN_ERR_BUSOFF) != 0) {
        bus_off_.fetch_add(1, std::memory_order_relaxed);
        mark_lost("bus-off", 0);
        return ReadStatus::kDeviceLost;
      }
      continue;
    }
    chunk.bytes = std::as_bytes(std::span<const std::uint8_t>(buffer_.data(), size));
    chunk.host_receive = received;
    chunk.channel = 0;
    counts_.count_chunk(size);
    return ReadStatus::kData;
  }
}

void SocketCanSource::request_stop() {
  stop_requested_.store(true, std::memory_order_release);
  if (stop_fd_ >= 0) {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t w = ::write(stop_fd_, &one, sizeof one);
  }
}

SourceCounters SocketCanSource::counters() const { return counts_.snapshot(); }

SocketCanCounters SocketCanSource::can_counters() const {
  return {error_frames_.load(std::memory_order_relaxed), bus_off_.load(std::memory_order_relaxed)};
}

}  // namespace posed::drivers::can
