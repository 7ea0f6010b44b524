#include "drivers/camera/realsense_imu_source.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::drivers::camera {

RealsenseImuSource::RealsenseImuSource(std::string name, RealsenseImuSourceConfig config)
    : name_(std::move(name)), config_(std::move(config)) {}

RealsenseImuSource::~RealsenseImuSource() { close(); }

std::string_view RealsenseImuSource::wire_format(std::uint32_t channel) const {
  return channel < 2 ? std::string_view(channels_[channel].wire_format) : std::string_view{};
}

void RealsenseImuSource::close() {
  for (auto& c : channels_) {
    if (c.fd >= 0) {
      ::close(c.fd);
      c.fd = -1;
      disable_iio_hid_device(c.device);
    }
    c.filled = c.delivered = 0;
  }
}

bool RealsenseImuSource::open(std::string& error) {
  if (channels_[0].fd >= 0) return true;
  const IioHidDeviceConfig* configs[2] = {&config_.accel, &config_.gyro};
  const std::string_view prefixes[2] = {wire::kIioAccel3d, wire::kIioGyro3d};
  for (int i = 0; i < 2; ++i) {
    Channel& c = channels_[i];
    if (!enable_iio_hid_device(*configs[i], c.device, error)) {
      error = "imu " + name_ + ": " + error;
      close();
      lost_ = true;  // read() looks for them again: a camera plugged in after start
      return false;
    }
    c.fd = ::open(c.device.dev_node.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (c.fd < 0) {
      error = "imu " + name_ + ": cannot open " + c.device.dev_node + ": " + std::strerror(errno);
      disable_iio_hid_device(c.device);
      close();
      lost_ = true;
      return false;
    }
    c.wire_format = describe_iio_layout(prefixes[i], c.device.layout);
    // Room for a full kernel buffer of records per read (librealsense reads hid_buf_len).
    c.buffer.assign(std::size_t{c.device.layout.record_bytes} * configs[i]->buffer_length, {});
    c.filled = c.delivered = 0;
  }
  return true;
}

bool RealsenseImuSource::deliver(std::uint32_t channel, RawChunk& chunk) {
  Channel& c = channels_[channel];
  const std::size_t record = c.device.layout.record_bytes;
  const std::size_t whole = (c.filled - c.delivered) / record * record;
  if (whole == 0) return false;
  chunk.bytes = std::span<const std::byte>(c.buffer.data() + c.delivered, whole);
  chunk.channel = channel;
  chunk.host_receive = host_now();
  c.delivered += whole;
  (channel == 0 ? imu_counters_.accel_records : imu_counters_.gyro_records) += whole / record;
  counts_.count_chunk(whole);
  return true;
}

ReadStatus RealsenseImuSource::read(RawChunk& chunk, Duration timeout) {
  if (stop_.load(std::memory_order_relaxed)) {
    close();
    return ReadStatus::kEndOfStream;
  }
  const int timeout_ms = static_cast<int>(std::max<std::int64_t>(0, timeout.ns / 1'000'000));
  if (channels_[0].fd < 0) {
    if (!lost_) return ReadStatus::kTimeout;  // open() never called: nothing to read
    ::poll(nullptr, 0, std::min(timeout_ms, config_.reopen_interval_ms));
    std::string error;
    if (!open(error)) return ReadStatus::kDeviceLost;
    lost_ = false;
    counts_.reopened.fetch_add(1, std::memory_order_relaxed);
    POSED_LOG_NOTICE("imu %s: IIO devices back, reopened", name_.c_str());
  }
  // The previous chunk's bytes are released now: move the partial tail to the front.
  for (auto& c : channels_) {
    if (c.delivered > 0) {
      std::memmove(c.buffer.data(), c.buffer.data() + c.delivered, c.filled - c.delivered);
      c.filled -= c.delivered;
      c.delivered = 0;
    }
  }
  // Records already read for the other channel go out before waiting for more.
  if (deliver(1, chunk) || deliver(0, chunk)) return ReadStatus::kData;
  pollfd fds[2] = {{channels_[0].fd, POLLIN, 0}, {channels_[1].fd, POLLIN, 0}};
  const int n = ::poll(fds, 2, timeout_ms);
  if (n <= 0) return ReadStatus::kTimeout;  // EINTR is a timeout too: the caller calls again
  for (std::uint32_t i = 0; i < 2; ++i) {
    Channel& c = channels_[i];
    if ((fds[i].revents & POLLIN) != 0) {
      const ssize_t got = ::read(c.fd, c.buffer.data() + c.filled, c.buffer.size() - c.filled);
      if (got > 0) {
        c.filled += static_cast<std::size_t>(got);
      } else if (got < 0 && errno != EAGAIN && errno != EINTR) {
        fds[i].revents |= POLLERR;
      }
    }
    if ((fds[i].revents & (POLLERR | POLLHUP | POLLNVAL)) != 0 && (fds[i].revents & POLLIN) == 0) {
      POSED_LOG_WARN("imu %s: %s gone (poll/read error); will reopen", name_.c_str(),
                     c.device.dev_node.c_str());
      ++imu_counters_.lost;
      close();
      lost_ = true;
      return ReadStatus::kDeviceLost;
    }
    if (c.filled == c.buffer.size() && c.filled % c.device.layout.record_bytes != 0) {
      // Cannot happen with whole-record kernel reads; guard so a full buffer never stalls.
      counts_.rejected.fetch_add(1, std::memory_order_relaxed);
      c.filled = 0;
    }
  }
  // Gyro first when both have data: it is the higher-rate stream.
  if (deliver(1, chunk) || deliver(0, chunk)) return ReadStatus::kData;
  return ReadStatus::kTimeout;
}

SourceCounters RealsenseImuSource::counters() const { return counts_.snapshot(); }

}  // namespace posed::drivers::camera
