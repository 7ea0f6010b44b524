#pragma once
// Replays the UDP datagrams of a pcap/pcapng capture through the same Source interface as the
// live socket: one port per channel, with the original timing, N× faster, or as fast as the
// reader reads. host_receive is the capture's time stamp (the recorded log time).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "drivers/common/source.hpp"
#include "drivers/common/wire_format.hpp"
#include "drivers/recording/mapped_file.hpp"
#include "drivers/recording/pcap_parser.hpp"
#include "drivers/recording/pcap_udp.hpp"

namespace posed::drivers::recording {

struct PcapSourceConfig {
  /// capture file (pcap or pcapng)
  std::string path;
  /// stream name for logs and status
  std::string name = "lidar";
  /// UDP destination port of each channel: channel i carries datagrams sent to ports[i]
  std::vector<std::uint16_t> ports = {2368, 8308};
  /// 1 = original timing, N = N× faster, 0 = as fast as read() is called
  double speed = 1.0;
};

/// What the file held besides the datagrams delivered.
struct PcapSourceStats {
  std::uint64_t records = 0;
  /// frames that are not UDP/IP (ARP, TCP, unsupported link, fragments)
  std::uint64_t not_udp = 0;
  /// UDP datagrams to other ports
  std::uint64_t other_ports = 0;
  /// datagrams cut short by the capture's snaplen or with inconsistent headers
  std::uint64_t damaged = 0;
};

class PcapSource final : public drivers::Source {
 public:
  explicit PcapSource(PcapSourceConfig config);

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

  PcapSourceStats stats() const;
  /// empty, or why the file ended early ("pcap F: truncated record at offset N (...)")
  std::string file_error() const;

 private:
  bool fetch_next();  // fills next_ with the next datagram on one of our ports

  PcapSourceConfig config_;
  MappedFile file_;
  PcapParser parser_{{}};
  bool opened_ = false;
  bool ended_ = false;

  // the datagram waiting to be delivered
  bool have_next_ = false;
  PcapRecord record_;
  UdpDatagram datagram_;
  std::uint32_t channel_ = 0;

  // pacing
  bool started_ = false;
  std::int64_t first_capture_ns_ = 0;
  HostTime first_host_;

  std::atomic<bool> stop_{false};
  std::mutex wait_mutex_;
  std::condition_variable wait_cv_;

  AtomicSourceCounters counts_;
  std::atomic<std::uint64_t> records_{0}, not_udp_{0}, other_ports_{0};
  mutable std::mutex error_mutex_;
  std::string file_error_;
};

}  // namespace posed::drivers::recording
