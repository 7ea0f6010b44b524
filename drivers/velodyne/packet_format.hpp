#pragma once
// The Velodyne data packet as the VLP-32C user manual (63-9325 Rev. B, section 9.3 "Data Packet
// Format") describes it; the VLP-16 and HDL-32E use the same layout. A 1206-byte UDP payload:
//   12 data blocks × 100 B: flag 0xFF 0xEE, azimuth u16 LE [0.01°], 32 × (distance u16 LE,
//   reflectivity u8) timestamp u32 LE [µs past the top of the hour] (time of the first firing of
//   the first block) factory bytes: return mode (0x37 strongest, 0x38 last, 0x39 dual), product id
// All multi-byte fields are little-endian.

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace posed::drivers::velodyne {

inline constexpr std::size_t kDataPacketBytes = 1206;
inline constexpr std::size_t kBlocksPerPacket = 12;
inline constexpr std::size_t kChannelsPerBlock = 32;
inline constexpr std::size_t kBlockBytes = 100;
inline constexpr std::size_t kChannelBytes = 3;
/// offset of the u32 timestamp [B]
inline constexpr std::size_t kTimestampOffset = kBlocksPerPacket * kBlockBytes;
/// offset of the return-mode factory byte [B]
inline constexpr std::size_t kReturnModeOffset = kTimestampOffset + 4;
/// offset of the product-id factory byte [B]
inline constexpr std::size_t kProductIdOffset = kReturnModeOffset + 1;
/// the two bytes every data block starts with (upper block flag; the HDL-64's 0xFFDD is not ours)
inline constexpr std::uint8_t kBlockFlag0 = 0xFF;
inline constexpr std::uint8_t kBlockFlag1 = 0xEE;
/// azimuth unit [0.01°] and its full turn
inline constexpr std::uint32_t kFullTurnCdeg = 36000;
/// the most points one packet can carry
inline constexpr std::size_t kMaxPointsPerPacket = kBlocksPerPacket * kChannelsPerBlock;

/// Factory byte 1 (manual table 9-1 "Factory Bytes").
enum class ReturnMode : std::uint8_t {
  kStrongest = 0x37,
  kLast = 0x38,
  kDual = 0x39,
};

/// Factory byte 2 (manual table 9-1).
enum class ProductId : std::uint8_t {
  kUnknown = 0x00,
  kHdl32e = 0x21,
  kVlp16 = 0x22,
  kVlp32c = 0x28,
};

constexpr bool is_known(ReturnMode m) {
  return m == ReturnMode::kStrongest || m == ReturnMode::kLast || m == ReturnMode::kDual;
}

constexpr std::string_view to_string(ReturnMode m) {
  switch (m) {
    case ReturnMode::kStrongest:
      return "strongest";
    case ReturnMode::kLast:
      return "last";
    case ReturnMode::kDual:
      return "dual";
  }
  return "unknown";
}

constexpr std::string_view to_string(ProductId p) {
  switch (p) {
    case ProductId::kHdl32e:
      return "HDL-32E";
    case ProductId::kVlp16:
      return "VLP-16";
    case ProductId::kVlp32c:
      return "VLP-32C";
    case ProductId::kUnknown:
      break;
  }
  return "unknown";
}

/// Little-endian reads from a byte pointer the caller has bounds-checked.
inline std::uint16_t read_u16_le(const std::byte* p) {
  return static_cast<std::uint16_t>(static_cast<unsigned>(p[0]) |
                                    (static_cast<unsigned>(p[1]) << 8));
}
inline std::uint32_t read_u32_le(const std::byte* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

}  // namespace posed::drivers::velodyne
