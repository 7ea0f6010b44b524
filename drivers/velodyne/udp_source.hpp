#pragma once
// The live Velodyne Source: two UDP sockets (data port 2368 → channel 0, position port 8308 →
// channel 1), woken by poll() with a timeout, drained with recvmmsg() in batches so one system
// call carries many 1206-byte datagrams (ros-drivers velodyne_driver input.cc does the same with
// poll + recvfrom). Datagrams from any address but the sensor's are counted and dropped.
// The sensor may be absent, unplugged and plugged back: UDP cannot tell, so silence is reported
// as timeouts (and logged once), and socket errors close the sockets and reopen them later.

#include <sys/socket.h>  // mmsghdr, sockaddr_storage
#include <sys/uio.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "drivers/common/source.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::drivers::velodyne {

struct UdpSourceConfig {
  /// stream name for logs and status
  std::string name = "lidar";
  /// only datagrams from this IPv4 address are accepted; "" accepts any sender
  std::string sensor_address = "192.168.1.201";
  /// local IPv4 address to bind; 0.0.0.0 keeps working while interfaces come and go
  std::string bind_address = "0.0.0.0";
  /// data packets (channel 0); 0 = an ephemeral port (tests)
  std::uint16_t data_port = 2368;
  /// position packets (channel 1); 0 = an ephemeral port (tests)
  std::uint16_t position_port = 8308;
  /// kernel receive buffer per socket; 4 MiB holds ~2.3 s of single-return data [B]
  int receive_buffer_bytes = 4 * 1024 * 1024;
  /// datagrams fetched per recvmmsg() call
  std::uint32_t batch = 64;
  /// no datagram for this long after data flowed logs "sensor silent" once [ns]
  Duration silence_warning = Duration::from_s(1);
};

/// Source-level counters beyond SourceCounters.
struct UdpSourceStats {
  /// datagrams from an address other than the sensor's
  std::uint64_t foreign = 0;
  /// datagrams larger than the receive slot (truncated by the kernel)
  std::uint64_t oversized = 0;
  /// times the stream went silent for longer than silence_warning
  std::uint64_t silences = 0;
  /// the socket receive buffer the kernel granted [B]
  std::uint64_t receive_buffer_bytes = 0;
};

class UdpSource final : public drivers::Source {
 public:
  explicit UdpSource(UdpSourceConfig config);
  ~UdpSource() override;
  UdpSource(const UdpSource&) = delete;
  UdpSource& operator=(const UdpSource&) = delete;

  std::string_view name() const override { return config_.name; }
  /// channel 0: data port, 1: position port
  std::string_view wire_format(std::uint32_t channel) const override {
    return channel == 0   ? wire::kVelodyneData
           : channel == 1 ? wire::kVelodynePosition
                          : std::string_view{};
  }
  bool open(std::string& error) override;
  ReadStatus read(RawChunk& chunk, Duration timeout) override;
  void request_stop() override;
  SourceCounters counters() const override;

  UdpSourceStats stats() const;
  /// the local port a channel is bound to (useful with port 0); 0 when closed
  std::uint16_t bound_port(std::uint32_t channel) const;

 private:
  static constexpr std::size_t kSlotBytes = 2048;  // > 1206 and 512, < any jumbo nonsense
  static constexpr int kChannels = 2;

  void close_sockets();
  bool open_socket(int channel, std::uint16_t port, std::string& error);
  /// receives a batch from `channel`; false on a socket error (device lost)
  bool receive(int channel);
  bool next_pending(RawChunk& chunk);

  UdpSourceConfig config_;
  std::uint32_t sensor_addr_be_ = 0;  // network byte order; 0 with any sender
  bool filter_sender_ = false;
  int fds_[kChannels] = {-1, -1};
  std::uint16_t ports_[kChannels] = {0, 0};
  int stop_fd_ = -1;
  bool opened_ = false;
  bool ever_opened_ = false;

  // recvmmsg batch storage per channel, allocated at open()
  std::vector<std::byte> slots_[kChannels];
  std::vector<::mmsghdr> headers_[kChannels];
  std::vector<::iovec> iovecs_[kChannels];
  std::vector<::sockaddr_storage> senders_[kChannels];
  unsigned received_[kChannels] = {0, 0};
  unsigned next_[kChannels] = {0, 0};
  HostTime batch_time_[kChannels];
  int next_channel_ = 0;  // alternates which channel's batch is served first

  HostTime last_data_;
  bool flowing_ = false;

  std::atomic<bool> stop_{false};
  AtomicSourceCounters counts_;
  std::atomic<std::uint64_t> foreign_{0}, oversized_{0}, silences_{0}, rcvbuf_{0};
};

}  // namespace posed::drivers::velodyne
