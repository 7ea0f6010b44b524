#include "drivers/camera/d4xx_hw_monitor.hpp"

#include <algorithm>

namespace posed::drivers::camera {
namespace {

void put_u16(std::vector<std::byte>& b, std::uint32_t v) {
  b.push_back(static_cast<std::byte>(v & 0xFF));
  b.push_back(static_cast<std::byte>((v >> 8) & 0xFF));
}
void put_u32(std::vector<std::byte>& b, std::uint32_t v) {
  put_u16(b, v & 0xFFFF);
  put_u16(b, v >> 16);
}
std::uint32_t get_u32(std::span<const std::byte> b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) | static_cast<std::uint32_t>(b[at + 1]) << 8 |
         static_cast<std::uint32_t>(b[at + 2]) << 16 | static_cast<std::uint32_t>(b[at + 3]) << 24;
}
std::uint16_t get_u16(std::span<const std::byte> b, std::size_t at) {
  return static_cast<std::uint16_t>(static_cast<std::uint32_t>(b[at]) |
                                    static_cast<std::uint32_t>(b[at + 1]) << 8);
}

}  // namespace

std::vector<std::byte> build_hwm_command(std::uint32_t opcode, std::uint32_t p1, std::uint32_t p2,
                                         std::uint32_t p3, std::uint32_t p4,
                                         std::span<const std::byte> data) {
  data = data.first(std::min(data.size(), kHwmMaxDataBytes));
  std::vector<std::byte> b;
  b.reserve(kHwmCommandHeaderBytes + data.size());
  // The length counts everything after itself and the magic (fill_usb_buffer: "Length doesn't
  // include header", header_size = 4).
  put_u16(b, static_cast<std::uint32_t>(kHwmCommandHeaderBytes - 4 + data.size()));
  put_u16(b, kHwmMagic);
  put_u32(b, opcode);
  for (std::uint32_t p : {p1, p2, p3, p4}) put_u32(b, p);
  b.insert(b.end(), data.begin(), data.end());
  return b;
}

bool parse_hwm_command(std::span<const std::byte> packet, HwmCommand& out) {
  if (packet.size() < kHwmCommandHeaderBytes) return false;
  if (get_u16(packet, 2) != kHwmMagic) return false;
  if (get_u16(packet, 0) + std::size_t{4} != packet.size()) return false;
  out.opcode = get_u32(packet, 4);
  for (std::size_t i = 0; i < 4; ++i) out.params[i] = get_u32(packet, 8 + 4 * i);
  out.data = packet.subspan(kHwmCommandHeaderBytes);
  return true;
}

std::string_view to_string(HwmStatus s) {
  switch (s) {
    case HwmStatus::kOk:
      return "ok";
    case HwmStatus::kTooShort:
      return "too_short";
    case HwmStatus::kWrongOpcode:
      return "wrong_opcode";
  }
  return "unknown";
}

HwmStatus parse_hwm_reply(std::span<const std::byte> reply, std::uint32_t opcode,
                          std::span<const std::byte>& payload, std::int32_t& echoed) {
  payload = {};
  echoed = 0;
  if (reply.size() < 4) return HwmStatus::kTooShort;
  const std::uint32_t e = get_u32(reply, 0);
  echoed = static_cast<std::int32_t>(e);
  if (e != opcode) return HwmStatus::kWrongOpcode;
  payload = reply.subspan(4);
  return HwmStatus::kOk;
}

}  // namespace posed::drivers::camera
