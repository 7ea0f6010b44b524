// libFuzzer target: the Velodyne data and position packet decoders and the scan assembler must
// accept any bytes without crashing, reading out of bounds or overflowing (ASan + UBSan), and
// keep their contracts: every call is counted exactly once, points stay within the raw range.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "drivers/velodyne/device_clock.hpp"
#include "drivers/velodyne/packet_decoder.hpp"
#include "drivers/velodyne/position_packet.hpp"
#include "drivers/velodyne/scan_assembler.hpp"

namespace vel = posed::drivers::velodyne;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static vel::PacketDecoder decoder;
  static vel::PacketDecoder framed_decoder({}, {.expected_product = vel::ProductId::kVlp32c});
  static posed::PayloadPool pool(2, 4096 * sizeof(posed::LidarPoint));
  static vel::ScanAssembler assembler(pool, {.cut_azimuth_cdeg = 9000});
  static vel::HourUnwrapper clock;
  static auto packet = std::make_unique<vel::DecodedPacket>();

  const auto bytes = std::span(reinterpret_cast<const std::byte*>(data), size);
  const auto before = decoder.counters().packets_ok + decoder.counters().malformed();
  // As sent, and framed: a 1206-byte window with valid flags so the body gets exercised.
  const bool ok = decoder.decode(bytes, *packet) == vel::DecodeStatus::kOk;
  if (decoder.counters().packets_ok + decoder.counters().malformed() != before + 1) std::abort();
  std::vector<std::byte> framed(vel::kDataPacketBytes, std::byte{0});
  std::memcpy(framed.data(), data, std::min(size, framed.size()));
  for (std::size_t b = 0; b < vel::kBlocksPerPacket; ++b) {
    framed[b * vel::kBlockBytes] = std::byte{0xFF};
    framed[b * vel::kBlockBytes + 1] = std::byte{0xEE};
    framed[b * vel::kBlockBytes + 3] = framed[b * vel::kBlockBytes + 3] & std::byte{0x7F};
  }
  framed[vel::kReturnModeOffset] =
      static_cast<std::byte>(0x37 + static_cast<int>(framed[vel::kReturnModeOffset]) % 3);
  framed[vel::kProductIdOffset] = std::byte{0x28};
  if (ok || framed_decoder.decode(framed, *packet) == vel::DecodeStatus::kOk) {
    if (packet->point_count > vel::kMaxPointsPerPacket) std::abort();
    for (std::uint32_t i = 0; i < packet->point_count; ++i) {
      const auto& p = packet->points[i];
      if (!(p.range_m <= 263.f) || p.azimuth_cdeg >= 36000 || p.block >= 12 || p.channel >= 32) {
        std::abort();
      }
    }
    assembler.add(*packet, clock.unwrap(packet->device_time_us));
    vel::AssembledScan scan;
    while (assembler.pop(scan)) {
      if (scan.scan.point_count > scan.scan.points.as<posed::LidarPoint>().size()) std::abort();
    }
  }
  vel::PositionPacket pos;
  (void)vel::parse_position_packet(bytes, pos);
  vel::GprmcFix fix;
  if (vel::parse_gprmc(std::string_view(reinterpret_cast<const char*>(data), size), fix)) {
    (void)vel::top_of_hour(fix, size > 4 ? vel::read_u32_le(bytes.data()) % 3'600'000'000u : 0);
  }
  return 0;
}
