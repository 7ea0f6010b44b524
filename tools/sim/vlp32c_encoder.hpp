#pragma once
// The VLP-32C wire format written by a simulator: the exact inverse of
// drivers/velodyne/packet_decoder (data packets) and position_packet (port 8308). Pure: no I/O,
// no allocation, no state.
//
// Data packet (manual 9.3): 12 blocks × (0xFF 0xEE, azimuth u16 LE [0.01°], 32 × (distance u16
// LE [4 mm], reflectivity u8)), timestamp u32 LE [µs past the hour] of block 0's first firing,
// return mode 0x37 (strongest), product 0x28 (VLP-32C).
// Position packet (manual 9.4): 512 B, timestamp u32 LE at 198, PPS status at 202, NMEA at 206.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "drivers/velodyne/packet_format.hpp"
#include "drivers/velodyne/position_packet.hpp"

namespace posed::sim {

/// One data block as the sensor fills it.
struct Vlp32cBlock {
  /// rotor azimuth at the block's first firing, 0..35999 [0.01°]
  std::uint16_t azimuth_cdeg = 0;
  /// raw distance per channel; 0 = no return [distance LSB, 4 mm]
  std::array<std::uint16_t, drivers::velodyne::kChannelsPerBlock> distance{};
  /// reflectivity per channel [0..255]
  std::array<std::uint8_t, drivers::velodyne::kChannelsPerBlock> reflectivity{};
};

struct Vlp32cPacket {
  std::array<Vlp32cBlock, drivers::velodyne::kBlocksPerPacket> blocks{};
  /// first firing of block 0 [µs past the top of the hour, < 3.6e9]
  std::uint32_t timestamp_us = 0;
  drivers::velodyne::ReturnMode return_mode = drivers::velodyne::ReturnMode::kStrongest;
  drivers::velodyne::ProductId product = drivers::velodyne::ProductId::kVlp32c;
};

/// Writes the 1206-byte payload; returns bytes written, 0 when `out` is too small.
std::size_t encode_vlp32c_packet(const Vlp32cPacket& packet, std::span<std::byte> out);

/// A $GPRMC sentence with checksum and CRLF ("$GPRMC,hhmmss,A,...*hh\r\n").
std::string make_gprmc(const drivers::velodyne::GprmcFix& fix);

/// Writes the 512-byte position packet; returns bytes written, 0 when `out` is too small or the
/// sentence does not fit its 128 bytes.
std::size_t encode_position_packet(std::uint32_t timestamp_us, drivers::velodyne::PpsStatus pps,
                                   const std::string& nmea, std::span<std::byte> out);

}  // namespace posed::sim
