#pragma once
// Sends recorded Velodyne payloads as UDP datagrams, as the sensor does: data packets (Source
// channel 0) to HOST:PORT, position packets (channel 1) to HOST:POSITION_PORT, one datagram per
// recorded chunk, byte for byte. Broadcast destinations are allowed (sensors often broadcast).
// Nobody listening is not an error, for a sensor or for us: the socket is unconnected, so an
// ICMP port-unreachable reply is not reported back. Counters are safe to read from any thread.

#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <string>

namespace posed::hil {

struct UdpTarget {
  /// IPv4 address or host name
  std::string host = "127.0.0.1";
  /// data packets (Source channel 0)
  std::uint16_t data_port = 2368;
  /// position packets (Source channel 1)
  std::uint16_t position_port = 8308;
};

/// Parses "HOST:PORT[,POSITION_PORT]" (position port defaults to 8308); false + `error`.
bool parse_udp_target(const std::string& text, UdpTarget& out, std::string& error);

struct UdpChannelCounters {
  std::uint64_t datagrams = 0;  ///< sent in full
  std::uint64_t bytes = 0;      ///< payload bytes sent [B]
  std::uint64_t failed = 0;     ///< send errors (network down, no route, ...)
};

class UdpEmitter {
 public:
  explicit UdpEmitter(UdpTarget target) : target_(std::move(target)) {}
  ~UdpEmitter();
  UdpEmitter(const UdpEmitter&) = delete;
  UdpEmitter& operator=(const UdpEmitter&) = delete;

  /// Resolves the host and opens the socket; false + `error` ("udp HOST:PORT: reason").
  bool open(std::string& error);
  /// One datagram to the port of `source_channel` (0 data, 1 position); false when it was not
  /// sent (counted). Channels above 1 are refused.
  bool send(std::uint32_t source_channel, std::span<const std::byte> payload);
  UdpChannelCounters counters(std::uint32_t source_channel) const;
  /// the last send error, for the summary ("" when none); read it once emission has ended
  const std::string& last_error() const { return last_error_; }
  const UdpTarget& target() const { return target_; }
  /// "127.0.0.1:2368" for channel 0
  std::string destination(std::uint32_t source_channel) const;

 private:
  UdpTarget target_;
  int fd_ = -1;
  std::uint32_t address_be_ = 0;  // resolved IPv4, network byte order
  struct AtomicCounters {
    std::atomic<std::uint64_t> datagrams{0}, bytes{0}, failed{0};
  };
  std::array<AtomicCounters, 2> counters_{};
  std::string last_error_;  // emitting thread only
};

}  // namespace posed::hil
