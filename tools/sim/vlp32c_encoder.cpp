#include "tools/sim/vlp32c_encoder.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

namespace posed::sim {
namespace vel = drivers::velodyne;
namespace {

void put_u16(std::byte* p, std::uint16_t v) {
  p[0] = static_cast<std::byte>(v & 0xFF);
  p[1] = static_cast<std::byte>(v >> 8);
}
void put_u32(std::byte* p, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) p[k] = static_cast<std::byte>((v >> (8 * k)) & 0xFF);
}

using vel::kNmeaBytes;
using vel::kNmeaOffset;
using vel::kPositionTimestampOffset;
using vel::kPpsOffset;

/// "ddmm.mmmm" with `deg_digits` degree digits.
std::string nmea_coordinate(double deg, int deg_digits) {
  const double a = std::abs(deg);
  const int whole = static_cast<int>(a);
  const double minutes = (a - whole) * 60.0;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%0*d%07.4f", deg_digits, whole, minutes);
  return buf;
}

}  // namespace

std::size_t encode_vlp32c_packet(const Vlp32cPacket& packet, std::span<std::byte> out) {
  if (out.size() < vel::kDataPacketBytes) return 0;
  std::byte* p = out.data();
  for (std::size_t b = 0; b < vel::kBlocksPerPacket; ++b) {
    std::byte* block = p + b * vel::kBlockBytes;
    const Vlp32cBlock& blk = packet.blocks[b];
    block[0] = std::byte{vel::kBlockFlag0};
    block[1] = std::byte{vel::kBlockFlag1};
    put_u16(block + 2, blk.azimuth_cdeg);
    for (std::size_t c = 0; c < vel::kChannelsPerBlock; ++c) {
      std::byte* ch = block + 4 + c * vel::kChannelBytes;
      put_u16(ch, blk.distance[c]);
      ch[2] = static_cast<std::byte>(blk.reflectivity[c]);
    }
  }
  put_u32(p + vel::kTimestampOffset, packet.timestamp_us);
  p[vel::kReturnModeOffset] = static_cast<std::byte>(packet.return_mode);
  p[vel::kProductIdOffset] = static_cast<std::byte>(packet.product);
  return vel::kDataPacketBytes;
}

std::string make_gprmc(const vel::GprmcFix& fix) {
  char body[128];
  std::snprintf(body, sizeof body, "GPRMC,%02u%02u%02u,%c,%s,%c,%s,%c,000.0,000.0,%02u%02u%02u,,,A",
                fix.hour, fix.minute, fix.second, fix.valid ? 'A' : 'V',
                nmea_coordinate(fix.latitude_deg, 2).c_str(), fix.latitude_deg < 0 ? 'S' : 'N',
                nmea_coordinate(fix.longitude_deg, 3).c_str(), fix.longitude_deg < 0 ? 'W' : 'E',
                fix.day, fix.month, fix.year % 100);
  std::uint8_t checksum = 0;
  for (const char* c = body; *c != '\0'; ++c) checksum ^= static_cast<std::uint8_t>(*c);
  char sentence[160];
  std::snprintf(sentence, sizeof sentence, "$%s*%02X\r\n", body, checksum);
  return sentence;
}

std::size_t encode_position_packet(std::uint32_t timestamp_us, vel::PpsStatus pps,
                                   const std::string& nmea, std::span<std::byte> out) {
  if (out.size() < vel::kPositionPacketBytes || nmea.size() > kNmeaBytes) return 0;
  std::memset(out.data(), 0, vel::kPositionPacketBytes);
  put_u32(out.data() + kPositionTimestampOffset, timestamp_us);
  out[kPpsOffset] = static_cast<std::byte>(pps);
  std::memcpy(out.data() + kNmeaOffset, nmea.data(), nmea.size());
  return vel::kPositionPacketBytes;
}

}  // namespace posed::sim
