#include "drivers/velodyne/udp_source.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"

namespace posed::drivers::velodyne {

UdpSource::UdpSource(UdpSourceConfig config) : config_(std::move(config)) {
  if (config_.batch == 0) config_.batch = 1;
}

UdpSource::~UdpSource() {
  close_sockets();
  if (stop_fd_ >= 0) ::close(stop_fd_);
}

void UdpSource::close_sockets() {
  for (int c = 0; c < kChannels; ++c) {
    if (fds_[c] >= 0) ::close(fds_[c]);
    fds_[c] = -1;
    ports_[c] = 0;
    received_[c] = next_[c] = 0;
  }
  opened_ = false;
}

bool UdpSource::open_socket(int channel, std::uint16_t port, std::string& error) {
  const std::string where =
      config_.name + " UDP " + config_.bind_address + ":" + std::to_string(port);
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    error = where + ": socket: " + std::strerror(errno);
    return false;
  }
  // A scan is ~150 datagrams in 100 ms; a deep buffer rides out scheduling hiccups.
  const int want = config_.receive_buffer_bytes;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &want, sizeof want);
  int got = 0;
  socklen_t len = sizeof got;
  ::getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &got, &len);
  // Linux reports twice the usable size it granted (socket(7)); below `want` means capped by
  // net.core.rmem_max. Privileged processes may exceed the cap with SO_RCVBUFFORCE.
  if (got / 2 < want) {
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &want, sizeof want);
    len = sizeof got;
    ::getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &got, &len);
    if (got / 2 < want) {
      POSED_LOG_WARN(
          "%s: kernel capped SO_RCVBUF at %d bytes (asked %d); raise "
          "net.core.rmem_max to avoid drops",
          where.c_str(), got / 2, want);
    }
  }
  rcvbuf_.store(static_cast<std::uint64_t>(got / 2), std::memory_order_relaxed);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  if (::inet_pton(AF_INET, config_.bind_address.c_str(), &addr.sin_addr) != 1) {
    error = where + ": bind address is not an IPv4 address";
    ::close(fd);
    return false;
  }
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    error = where + ": bind: " + std::strerror(errno);
    ::close(fd);
    return false;
  }
  sockaddr_in bound{};
  socklen_t blen = sizeof bound;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &blen);
  fds_[channel] = fd;
  ports_[channel] = ntohs(bound.sin_port);

  // recvmmsg storage: `batch` slots of kSlotBytes, their iovecs and sender addresses.
  const std::size_t n = config_.batch;
  slots_[channel].assign(n * kSlotBytes, std::byte{0});
  headers_[channel].assign(n, ::mmsghdr{});
  iovecs_[channel].assign(n, ::iovec{});
  senders_[channel].assign(n, ::sockaddr_storage{});
  for (std::size_t i = 0; i < n; ++i) {
    iovecs_[channel][i].iov_base = slots_[channel].data() + i * kSlotBytes;
    iovecs_[channel][i].iov_len = kSlotBytes;
  }
  return true;
}

bool UdpSource::open(std::string& error) {
  if (opened_) return true;
  if (stop_fd_ < 0) {
    stop_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (stop_fd_ < 0) {
      error = config_.name + ": eventfd: " + std::strerror(errno);
      return false;
    }
  }
  filter_sender_ = !config_.sensor_address.empty();
  if (filter_sender_) {
    in_addr a{};
    if (::inet_pton(AF_INET, config_.sensor_address.c_str(), &a) != 1) {
      error =
          config_.name + ": sensor address '" + config_.sensor_address + "' is not an IPv4 address";
      return false;
    }
    sensor_addr_be_ = a.s_addr;
  }
  if (!open_socket(0, config_.data_port, error) || !open_socket(1, config_.position_port, error)) {
    close_sockets();
    return false;
  }
  opened_ = true;
  ever_opened_ = true;
  return true;
}

bool UdpSource::receive(int channel) {
  const std::size_t n = config_.batch;
  for (std::size_t i = 0; i < n; ++i) {
    ::msghdr& h = headers_[channel][i].msg_hdr;
    h = ::msghdr{};
    h.msg_iov = &iovecs_[channel][i];
    h.msg_iovlen = 1;
    h.msg_name = &senders_[channel][i];
    h.msg_namelen = sizeof(::sockaddr_storage);
    headers_[channel][i].msg_len = 0;
  }
  const int got = ::recvmmsg(fds_[channel], headers_[channel].data(), static_cast<unsigned>(n),
                             MSG_DONTWAIT, nullptr);
  if (got < 0) {
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return true;
    // ECONNREFUSED and friends are ICMP leftovers on a UDP socket, not a lost device.
    if (errno == ECONNREFUSED || errno == EHOSTUNREACH || errno == ENETUNREACH) return true;
    POSED_LOG_WARN("%s: recvmmsg on port %u: %s; reopening", config_.name.c_str(),
                   static_cast<unsigned>(ports_[channel]), std::strerror(errno));
    return false;
  }
  received_[channel] = static_cast<unsigned>(got);
  next_[channel] = 0;
  batch_time_[channel] = host_now();
  return true;
}

bool UdpSource::next_pending(RawChunk& chunk) {
  for (int k = 0; k < kChannels; ++k) {
    const int c = (next_channel_ + k) % kChannels;
    while (next_[c] < received_[c]) {
      const unsigned i = next_[c]++;
      const ::mmsghdr& m = headers_[c][i];
      const auto* sender = reinterpret_cast<const sockaddr_in*>(&senders_[c][i]);
      if (filter_sender_ &&
          (sender->sin_family != AF_INET || sender->sin_addr.s_addr != sensor_addr_be_)) {
        foreign_.fetch_add(1, std::memory_order_relaxed);
        counts_.rejected.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      if ((m.msg_hdr.msg_flags & MSG_TRUNC) != 0 || m.msg_len > kSlotBytes) {
        oversized_.fetch_add(1, std::memory_order_relaxed);
        counts_.rejected.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      chunk.bytes =
          std::span<const std::byte>(slots_[c].data() + std::size_t{i} * kSlotBytes, m.msg_len);
      chunk.host_receive = batch_time_[c];
      chunk.channel = static_cast<std::uint32_t>(c);
      counts_.count_chunk(m.msg_len);
      next_channel_ = (c + 1) % kChannels;
      return true;
    }
  }
  return false;
}

ReadStatus UdpSource::read(RawChunk& chunk, Duration timeout) {
  if (stop_.load(std::memory_order_acquire)) return ReadStatus::kEndOfStream;
  if (!opened_) {
    std::string error;
    if (!open(error)) {
      POSED_LOG_WARN("%s", error.c_str());
      // Do not spin: wait out the timeout before the caller retries.
      ::pollfd p{stop_fd_, POLLIN, 0};
      ::poll(&p, stop_fd_ >= 0 ? 1 : 0, static_cast<int>(timeout.ns / 1'000'000));
      return stop_.load() ? ReadStatus::kEndOfStream : ReadStatus::kDeviceLost;
    }
    if (ever_opened_) counts_.reopened.fetch_add(1, std::memory_order_relaxed);
  }
  const HostTime deadline = host_now() + timeout;
  for (;;) {
    if (next_pending(chunk)) {
      last_data_ = chunk.host_receive;
      if (!flowing_) {
        if (silences_.load(std::memory_order_relaxed) > 0) {
          POSED_LOG_NOTICE("%s: datagrams flowing again", config_.name.c_str());
        }
        flowing_ = true;
      }
      return ReadStatus::kData;
    }
    const Duration left = deadline - host_now();
    ::pollfd fds[kChannels + 1];
    fds[0] = {stop_fd_, POLLIN, 0};
    for (int c = 0; c < kChannels; ++c) fds[c + 1] = {fds_[c], POLLIN, 0};
    // Round the wait up to whole milliseconds so a short timeout still waits.
    const int ms = left.ns <= 0 ? 0 : static_cast<int>((left.ns + 999'999) / 1'000'000);
    const int r = ::poll(fds, kChannels + 1, ms);
    if (stop_.load(std::memory_order_acquire)) return ReadStatus::kEndOfStream;
    if (r < 0 && errno != EINTR) {
      POSED_LOG_WARN("%s: poll: %s; reopening", config_.name.c_str(), std::strerror(errno));
      close_sockets();
      return ReadStatus::kDeviceLost;
    }
    bool any = false;
    for (int c = 0; c < kChannels; ++c) {
      if ((fds[c + 1].revents & (POLLIN | POLLERR)) == 0) continue;
      any = true;
      if (!receive(c)) {
        close_sockets();
        return ReadStatus::kDeviceLost;
      }
    }
    if (!any && host_now() >= deadline) {
      if (flowing_ && host_now() - last_data_ >= config_.silence_warning) {
        flowing_ = false;
        silences_.fetch_add(1, std::memory_order_relaxed);
        POSED_LOG_WARN(
            "%s: no datagram from %s for %.1f s (sensor unplugged or off?)", config_.name.c_str(),
            config_.sensor_address.empty() ? "any sender" : config_.sensor_address.c_str(),
            (host_now() - last_data_).seconds());
      }
      return ReadStatus::kTimeout;
    }
  }
}

void UdpSource::request_stop() {
  stop_.store(true, std::memory_order_release);
  if (stop_fd_ >= 0) {
    const std::uint64_t one = 1;
    [[maybe_unused]] const auto n = ::write(stop_fd_, &one, sizeof one);
  }
}

SourceCounters UdpSource::counters() const { return counts_.snapshot(); }

UdpSourceStats UdpSource::stats() const {
  UdpSourceStats s;
  s.foreign = foreign_.load(std::memory_order_relaxed);
  s.oversized = oversized_.load(std::memory_order_relaxed);
  s.silences = silences_.load(std::memory_order_relaxed);
  s.receive_buffer_bytes = rcvbuf_.load(std::memory_order_relaxed);
  return s;
}

std::uint16_t UdpSource::bound_port(std::uint32_t channel) const {
  return channel < kChannels ? ports_[channel] : 0;
}

}  // namespace posed::drivers::velodyne
