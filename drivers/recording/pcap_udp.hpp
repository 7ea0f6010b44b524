#pragma once
// Finds the UDP datagram inside a captured frame: link layer (Ethernet with 802.1Q/802.1ad tags,
// Linux cooked capture v1 and v2, raw IPv4/IPv6, BSD loopback), then IPv4 or IPv6, then UDP.
// Pure; never reads outside `frame`. Link-type numbers from tcpdump.org/linktypes.html.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace posed::drivers::recording {

namespace linktype {
inline constexpr std::uint32_t kNull = 0;  ///< BSD loopback: 4-byte host-order family
inline constexpr std::uint32_t kEthernet = 1;
inline constexpr std::uint32_t kRawOpenBsd = 12;  ///< DLT_RAW on some BSDs
inline constexpr std::uint32_t kRaw = 101;        ///< raw IPv4/IPv6
inline constexpr std::uint32_t kLinuxSll = 113;   ///< Linux cooked capture v1 (16-byte header)
inline constexpr std::uint32_t kIpv4 = 228;
inline constexpr std::uint32_t kIpv6 = 229;
inline constexpr std::uint32_t kLinuxSll2 = 276;  ///< Linux cooked capture v2 (20-byte header)
}  // namespace linktype

enum class FrameStatus : std::uint8_t {
  kOk,
  kUnsupportedLink,  ///< a link type this reader does not decode
  kNotIp,            ///< ARP, LLDP, ... (not an error: captures hold other traffic)
  kNotUdp,           ///< TCP, ICMP, ...
  kFragment,         ///< an IPv4 fragment (Velodyne datagrams fit one frame)
  kTruncated,        ///< the capture cut the frame before the end of the UDP payload
  kMalformed,        ///< header lengths that contradict each other
};

std::string_view to_string(FrameStatus s);

struct UdpDatagram {
  /// source and destination address, IPv4 in the first 4 bytes
  std::array<std::uint8_t, 16> src_addr{}, dst_addr{};
  /// 4 or 6
  std::uint8_t ip_version = 4;
  std::uint16_t src_port = 0, dst_port = 0;
  /// the UDP payload (UDP length, not the frame's padding)
  std::span<const std::byte> payload;
};

FrameStatus extract_udp(std::uint32_t link_type, std::span<const std::byte> frame,
                        UdpDatagram& out) noexcept;

/// "192.168.1.201" / IPv6 text of an address in a UdpDatagram.
std::string address_to_string(const std::array<std::uint8_t, 16>& addr, std::uint8_t ip_version);

}  // namespace posed::drivers::recording
