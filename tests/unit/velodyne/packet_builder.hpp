#pragma once
// Builds Velodyne data packets by hand (the layout of packet_format.hpp) for synthetic tests.

#include <cstdint>
#include <functional>
#include <vector>

#include "drivers/velodyne/packet_format.hpp"

namespace posed::test {

struct PacketSpec {
  /// azimuth of block 0 [0.01°] and per firing [0.01°]
  std::uint32_t azimuth_cdeg = 0;
  std::uint32_t step_cdeg = 20;
  std::uint32_t time_us = 0;
  std::uint8_t mode = 0x37;
  std::uint8_t product = 0x28;
  /// raw distance for (block, channel); default 2500 (10 m at 4 mm)
  std::function<std::uint16_t(std::uint32_t, std::uint32_t)> distance =
      [](std::uint32_t, std::uint32_t) -> std::uint16_t { return 2500; };
};

inline std::vector<std::byte> make_packet(const PacketSpec& s) {
  using namespace drivers::velodyne;
  std::vector<std::byte> p(kDataPacketBytes, std::byte{0});
  const bool dual = s.mode == 0x39;
  for (std::uint32_t b = 0; b < kBlocksPerPacket; ++b) {
    std::byte* block = p.data() + b * kBlockBytes;
    block[0] = std::byte{0xFF};
    block[1] = std::byte{0xEE};
    const std::uint32_t firing = dual ? b / 2 : b;
    const auto az = static_cast<std::uint16_t>((s.azimuth_cdeg + firing * s.step_cdeg) % 36000);
    block[2] = static_cast<std::byte>(az & 0xFF);
    block[3] = static_cast<std::byte>(az >> 8);
    for (std::uint32_t c = 0; c < kChannelsPerBlock; ++c) {
      const std::uint16_t d = s.distance(b, c);
      block[4 + 3 * c] = static_cast<std::byte>(d & 0xFF);
      block[5 + 3 * c] = static_cast<std::byte>(d >> 8);
      block[6 + 3 * c] = static_cast<std::byte>(c * 7);
    }
  }
  for (int i = 0; i < 4; ++i) {
    p[kTimestampOffset + static_cast<std::size_t>(i)] =
        static_cast<std::byte>((s.time_us >> (8 * i)) & 0xFF);
  }
  p[kReturnModeOffset] = static_cast<std::byte>(s.mode);
  p[kProductIdOffset] = static_cast<std::byte>(s.product);
  return p;
}

}  // namespace posed::test
