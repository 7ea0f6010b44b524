#pragma once
// Pure decoder for Velodyne data packets (VLP-32C, VLP-16, HDL-32E): bytes in, points out, in
// the sensor frame x forward, y left, z up (ROS REP-103). It never throws on bad input and never
// allocates after the first packet of a model: a bad packet yields a status and a counter.
//
// Per point (manual section 9.5 "Calculating X, Y, Z Coordinates" and 9.6 "Precision Azimuth"):
//   range     = raw_distance · resolution + dist_correction
//   azimuth   = block azimuth + rotation since the block's first firing (interpolated from the
//               next firing's azimuth) − rot_correction of the laser
//   time      = firing index · firing cycle + the channel's offset in the cycle

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "drivers/velodyne/calibration.hpp"
#include "drivers/velodyne/packet_format.hpp"
#include "drivers/velodyne/sensor_model.hpp"

namespace posed::drivers::velodyne {

struct DecoderConfig {
  /// returns closer than this are dropped (a raw distance of 0 means "no return" and is always
  /// dropped) [m]
  double min_range_m = 0.0;
  /// returns farther than this are dropped [m]
  double max_range_m = 300.0;
  /// the product the calibration is for; kUnknown = accept the first known product whose laser
  /// count matches the calibration and reject any other afterwards
  ProductId expected_product = ProductId::kUnknown;
};

enum class DecodeStatus : std::uint8_t {
  kOk,
  kWrongSize,          ///< payload is not 1206 bytes (short, oversized, or another packet type)
  kBadBlockFlag,       ///< a block does not start with 0xFF 0xEE
  kBadAzimuth,         ///< a block azimuth > 360.00° (360.00° itself is sent and means 0°)
  kUnknownReturnMode,  ///< factory byte 1 is not 0x37/0x38/0x39
  kUnknownProduct,     ///< factory byte 2 is not a product this decoder knows
  kModelMismatch,      ///< product differs from the configured/locked one or from the calibration
};

std::string_view to_string(DecodeStatus s);

/// One return in the sensor frame.
struct DecodedPoint {
  /// position [m], x forward, y left, z up
  float x_m = 0.f, y_m = 0.f, z_m = 0.f;
  /// corrected range along the beam [m]
  float range_m = 0.f;
  /// firing time relative to the packet's first firing (its timestamp) [ns]
  std::int32_t t_ns = 0;
  /// precise azimuth of the beam, Velodyne convention (clockwise from x seen from above) [0.01°]
  std::uint16_t azimuth_cdeg = 0;
  /// reflectivity as sent [0..255]
  std::uint8_t intensity = 0;
  /// data block in the packet [0..11]
  std::uint8_t block = 0;
  /// channel within the block [0..31]
  std::uint8_t channel = 0;
  /// laser id (the calibration row) [0..31]
  std::uint8_t laser = 0;
  /// ring: lasers ordered by elevation, 0 = lowest
  std::uint8_t ring = 0;
  /// 0 = the only/last return, 1 = the strongest return when it differs from the last (dual)
  std::uint8_t return_index = 0;
};

struct DecodedPacket {
  ProductId product = ProductId::kUnknown;
  ReturnMode return_mode = ReturnMode::kStrongest;
  /// the packet's timestamp: first firing of block 0 [µs past the top of the hour]
  std::uint32_t device_time_us = 0;
  /// block azimuths as sent, 0..36000 (some firmware sends 36000 for 0) [0.01°]
  std::array<std::uint16_t, kBlocksPerPacket> block_azimuth_cdeg{};
  /// firings in this packet (12 single return, 6 dual)
  std::uint32_t firing_count = 0;
  /// time between firings [ns]
  std::int32_t firing_period_ns = 0;
  /// rotation speed from the azimuth change across the packet; 0 when not measurable [rpm]
  float rpm = 0.f;
  /// valid entries in `points`, in block then channel order
  std::uint32_t point_count = 0;
  /// channels with raw distance 0
  std::uint32_t no_return_count = 0;
  /// returns outside [min_range_m, max_range_m]
  std::uint32_t out_of_range_count = 0;
  /// dual mode: strongest returns equal to the last return, not repeated
  std::uint32_t dual_duplicate_count = 0;
  std::array<DecodedPoint, kMaxPointsPerPacket> points{};

  /// the firing a block belongs to (blocks pair up in dual return mode)
  std::uint32_t firing_of_block(std::uint32_t block) const {
    return return_mode == ReturnMode::kDual ? block / 2 : block;
  }
};

struct DecoderCounters {
  std::uint64_t packets_ok = 0;
  std::uint64_t wrong_size = 0;
  std::uint64_t bad_block_flag = 0;
  std::uint64_t bad_azimuth = 0;
  std::uint64_t unknown_return_mode = 0;
  std::uint64_t unknown_product = 0;
  std::uint64_t model_mismatch = 0;
  /// points emitted
  std::uint64_t points = 0;
  std::uint64_t malformed() const {
    return wrong_size + bad_block_flag + bad_azimuth + unknown_return_mode + unknown_product +
           model_mismatch;
  }
};

/// Only checks the header fields; for routing and inspection without a calibration.
DecodeStatus peek_data_packet(std::span<const std::byte> payload, ProductId& product,
                              ReturnMode& mode) noexcept;

class PacketDecoder {
 public:
  /// An empty `calibration` means the manual's nominal table for the product first seen.
  explicit PacketDecoder(Calibration calibration = {}, DecoderConfig config = {});

  /// Decodes one UDP payload into `out` (overwritten). `out` is unspecified unless kOk.
  DecodeStatus decode(std::span<const std::byte> payload, DecodedPacket& out) noexcept;

  const DecoderCounters& counters() const { return counters_; }
  /// the product the decoder has locked onto (kUnknown before the first good packet)
  ProductId product() const { return product_; }
  const Calibration& calibration() const { return calibration_; }

 private:
  bool lock_model(ProductId product) noexcept;

  Calibration calibration_;
  DecoderConfig config_;
  DecoderCounters counters_;
  ProductId product_ = ProductId::kUnknown;
  const SensorModel* model_ = nullptr;
  float distance_resolution_m_ = 0.f;
  float min_range_m_ = 0.f;
  float max_range_m_ = 0.f;

  /// per channel of a block, for the locked model
  struct ChannelTable {
    float cos_rot, sin_rot;  // of -rot_correction folded in below
    float rot_cdeg;          // rot_correction [0.01°]
    float cos_vert, sin_vert;
    float dist_correction_m, vert_offset_m, horiz_offset_m;
    float fraction_of_firing;  // channel offset / firing period
    std::int32_t offset_ns;
    std::uint8_t laser, ring;
  };
  std::array<ChannelTable, kChannelsPerBlock> channels_{};
};

}  // namespace posed::drivers::velodyne
