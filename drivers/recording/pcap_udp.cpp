#include "drivers/recording/pcap_udp.hpp"

#include <arpa/inet.h>

#include <cstring>

namespace posed::drivers::recording {
namespace {

constexpr std::uint16_t kEtherIpv4 = 0x0800;
constexpr std::uint16_t kEtherIpv6 = 0x86DD;
constexpr std::uint16_t kEtherVlan = 0x8100;
constexpr std::uint16_t kEtherQinQ = 0x88A8;
constexpr std::uint8_t kProtoUdp = 17;

std::uint16_t be16(const std::byte* p) {
  return static_cast<std::uint16_t>((static_cast<unsigned>(p[0]) << 8) |
                                    static_cast<unsigned>(p[1]));
}

FrameStatus parse_udp(std::span<const std::byte> l4, std::uint32_t ip_payload_len,
                      UdpDatagram& out) {
  if (ip_payload_len < 8) return FrameStatus::kMalformed;
  if (l4.size() < 8) return FrameStatus::kTruncated;
  out.src_port = be16(l4.data());
  out.dst_port = be16(l4.data() + 2);
  const std::uint16_t udp_len = be16(l4.data() + 4);
  if (udp_len < 8 || udp_len > ip_payload_len) return FrameStatus::kMalformed;
  if (udp_len > l4.size()) return FrameStatus::kTruncated;
  out.payload = l4.subspan(8, udp_len - 8u);
  return FrameStatus::kOk;
}

FrameStatus parse_ipv4(std::span<const std::byte> ip, UdpDatagram& out) {
  if (ip.size() < 20) return FrameStatus::kTruncated;
  const auto b0 = static_cast<std::uint8_t>(ip[0]);
  if ((b0 >> 4) != 4) return FrameStatus::kMalformed;
  const std::size_t ihl = (b0 & 0x0Fu) * 4u;
  const std::uint16_t total = be16(ip.data() + 2);
  if (ihl < 20 || total < ihl) return FrameStatus::kMalformed;
  if (ip.size() < ihl) return FrameStatus::kTruncated;
  const std::uint16_t frag = be16(ip.data() + 6);
  if ((frag & 0x3FFF) != 0) return FrameStatus::kFragment;  // MF flag or a fragment offset
  if (static_cast<std::uint8_t>(ip[9]) != kProtoUdp) return FrameStatus::kNotUdp;
  out.ip_version = 4;
  out.src_addr = {};
  out.dst_addr = {};
  std::memcpy(out.src_addr.data(), ip.data() + 12, 4);
  std::memcpy(out.dst_addr.data(), ip.data() + 16, 4);
  return parse_udp(ip.subspan(ihl), total - static_cast<std::uint32_t>(ihl), out);
}

FrameStatus parse_ipv6(std::span<const std::byte> ip, UdpDatagram& out) {
  if (ip.size() < 40) return FrameStatus::kTruncated;
  if ((static_cast<std::uint8_t>(ip[0]) >> 4) != 6) return FrameStatus::kMalformed;
  // Extension headers are not followed: sensors send plain UDP.
  if (static_cast<std::uint8_t>(ip[6]) != kProtoUdp) return FrameStatus::kNotUdp;
  out.ip_version = 6;
  std::memcpy(out.src_addr.data(), ip.data() + 8, 16);
  std::memcpy(out.dst_addr.data(), ip.data() + 24, 16);
  return parse_udp(ip.subspan(40), be16(ip.data() + 4), out);
}

FrameStatus parse_ip(std::span<const std::byte> ip, UdpDatagram& out) {
  if (ip.empty()) return FrameStatus::kTruncated;
  switch (static_cast<std::uint8_t>(ip[0]) >> 4) {
    case 4:
      return parse_ipv4(ip, out);
    case 6:
      return parse_ipv6(ip, out);
    default:
      return FrameStatus::kNotIp;
  }
}

FrameStatus parse_ethertype(std::uint16_t type, std::span<const std::byte> rest, UdpDatagram& out) {
  if (type == kEtherIpv4) return parse_ipv4(rest, out);
  if (type == kEtherIpv6) return parse_ipv6(rest, out);
  return FrameStatus::kNotIp;
}

}  // namespace

std::string_view to_string(FrameStatus s) {
  switch (s) {
    case FrameStatus::kOk:
      return "ok";
    case FrameStatus::kUnsupportedLink:
      return "unsupported_link";
    case FrameStatus::kNotIp:
      return "not_ip";
    case FrameStatus::kNotUdp:
      return "not_udp";
    case FrameStatus::kFragment:
      return "fragment";
    case FrameStatus::kTruncated:
      return "truncated";
    case FrameStatus::kMalformed:
      return "malformed";
  }
  return "unknown";
}

FrameStatus extract_udp(std::uint32_t link_type, std::span<const std::byte> frame,
                        UdpDatagram& out) noexcept {
  switch (link_type) {
    case linktype::kEthernet: {
      if (frame.size() < 14) return FrameStatus::kTruncated;
      std::size_t at = 12;
      std::uint16_t type = be16(frame.data() + at);
      // Up to two VLAN tags (802.1ad outer, 802.1Q inner).
      for (int tags = 0; (type == kEtherVlan || type == kEtherQinQ) && tags < 2; ++tags) {
        at += 4;
        if (frame.size() < at + 2) return FrameStatus::kTruncated;
        type = be16(frame.data() + at);
      }
      return parse_ethertype(type, frame.subspan(at + 2), out);
    }
    case linktype::kLinuxSll:
      if (frame.size() < 16) return FrameStatus::kTruncated;
      return parse_ethertype(be16(frame.data() + 14), frame.subspan(16), out);
    case linktype::kLinuxSll2:
      if (frame.size() < 20) return FrameStatus::kTruncated;
      return parse_ethertype(be16(frame.data()), frame.subspan(20), out);
    case linktype::kRaw:
    case linktype::kRawOpenBsd:
      return parse_ip(frame, out);
    case linktype::kIpv4:
      return parse_ipv4(frame, out);
    case linktype::kIpv6:
      return parse_ipv6(frame, out);
    case linktype::kNull:
      if (frame.size() < 4) return FrameStatus::kTruncated;
      return parse_ip(frame.subspan(4), out);  // the family word's byte order varies; sniff IP
    default:
      return FrameStatus::kUnsupportedLink;
  }
}

std::string address_to_string(const std::array<std::uint8_t, 16>& addr, std::uint8_t ip_version) {
  char buf[INET6_ADDRSTRLEN] = {};
  ::inet_ntop(ip_version == 6 ? AF_INET6 : AF_INET, addr.data(), buf, sizeof buf);
  return buf;
}

}  // namespace posed::drivers::recording
