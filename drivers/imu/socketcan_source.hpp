#pragma once
// Live SocketCAN Source: a CAN_RAW socket (classic + FD) bound to one interface, with kernel ID
// filters. Each read() returns one frame in kernel byte form (can_frame.hpp). Error frames are
// counted, not returned; bus-off and a downed interface close the socket and reopen it with
// back-off (the controller itself is restarted by the kernel: `ip link set canX type can
// restart-ms N`).

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "drivers/common/source.hpp"
#include "drivers/common/wire_format.hpp"
#include "drivers/imu/can_frame.hpp"

namespace posed::drivers::can {

/// Kernel acceptance filter: a frame passes when (id & mask) == (filter_id & mask).
struct CanFilter {
  /// ID to match, flag bits included as in linux/can.h (CAN_EFF_FLAG for 29-bit IDs)
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
};

struct SocketCanConfig {
  /// interface name, e.g. "can0"
  std::string interface = "can0";
  /// receive CAN FD frames too
  bool fd_frames = true;
  /// empty = accept every frame
  std::vector<CanFilter> filters{};
  /// first reopen delay after bus-off / interface down [ns]
  Duration reopen_backoff_min = Duration::from_ms(100);
  /// reopen delay cap [ns]
  Duration reopen_backoff_max = Duration::from_s(2);
  std::string name = "imu_can";
};

struct SocketCanCounters {
  /// error frames received (any class)
  std::uint64_t error_frames = 0;
  /// of which bus-off
  std::uint64_t bus_off = 0;
};

class SocketCanSource final : public Source {
 public:
  explicit SocketCanSource(SocketCanConfig config);
  ~SocketCanSource() override;
  SocketCanSource(const SocketCanSource&) = delete;
  SocketCanSource& operator=(const SocketCanSource&) = delete;

  std::string_view name() const override { return config_.name; }
  std::string_view wire_format(std::uint32_t channel) const override {
    return channel == 0 ? wire::kCanFrame : std::string_view{};
  }
  bool open(std::string& error) override;
  ReadStatus read(RawChunk& chunk, Duration timeout) override;
  void request_stop() override;
  SourceCounters counters() const override;
  SocketCanCounters can_counters() const;

 private:
  bool open_socket(std::string& error);
  void close_socket();
  void mark_lost(const char* why, int err);

  SocketCanConfig config_;
  int fd_ = -1;
  int stop_fd_ = -1;
  std::atomic<bool> stop_requested_{false};
  bool ever_opened_ = false;
  HostTime next_reopen_;
  Duration backoff_;
  std::array<std::uint8_t, kCanFdMtu> buffer_{};
  AtomicSourceCounters counts_;
  std::atomic<std::uint64_t> error_frames_{0}, bus_off_{0};
};

}  // namespace posed::drivers::can
