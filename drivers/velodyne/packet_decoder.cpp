#include "drivers/velodyne/packet_decoder.hpp"

#include <cmath>
#include <numbers>

namespace posed::drivers::velodyne {
namespace {

/// cos/sin of every whole 0.01° (block azimuths are whole 0.01°), built once.
struct AzimuthTable {
  std::vector<float> cos_v, sin_v;
  AzimuthTable() : cos_v(kFullTurnCdeg), sin_v(kFullTurnCdeg) {
    for (std::uint32_t i = 0; i < kFullTurnCdeg; ++i) {
      const double a = static_cast<double>(i) * std::numbers::pi / 18000.0;
      cos_v[i] = static_cast<float>(std::cos(a));
      sin_v[i] = static_cast<float>(std::sin(a));
    }
  }
};

const AzimuthTable& azimuth_table() {
  static const AzimuthTable table;
  return table;
}

constexpr float kCdegToRad = static_cast<float>(std::numbers::pi / 18000.0);
/// A rotation between two firings larger than this is not a rotation but a glitch (or a packet
/// built by hand): 1200 rpm, the fastest setting, turns the VLP-16's 110.6 µs block by 0.8°.
constexpr std::uint32_t kMaxFiringGapCdeg = 100;

}  // namespace

std::string_view to_string(DecodeStatus s) {
  switch (s) {
    case DecodeStatus::kOk:
      return "ok";
    case DecodeStatus::kWrongSize:
      return "wrong_size";
    case DecodeStatus::kBadBlockFlag:
      return "bad_block_flag";
    case DecodeStatus::kBadAzimuth:
      return "bad_azimuth";
    case DecodeStatus::kUnknownReturnMode:
      return "unknown_return_mode";
    case DecodeStatus::kUnknownProduct:
      return "unknown_product";
    case DecodeStatus::kModelMismatch:
      return "model_mismatch";
  }
  return "unknown";
}

DecodeStatus peek_data_packet(std::span<const std::byte> payload, ProductId& product,
                              ReturnMode& mode) noexcept {
  if (payload.size() != kDataPacketBytes) return DecodeStatus::kWrongSize;
  const std::byte* p = payload.data();
  for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
    const std::byte* block = p + b * kBlockBytes;
    if (block[0] != std::byte{kBlockFlag0} || block[1] != std::byte{kBlockFlag1}) {
      return DecodeStatus::kBadBlockFlag;
    }
    // 360.00° itself occurs (a real HDL-32E capture has it) and means 0°.
    if (read_u16_le(block + 2) > kFullTurnCdeg) return DecodeStatus::kBadAzimuth;
  }
  mode = static_cast<ReturnMode>(p[kReturnModeOffset]);
  if (!is_known(mode)) return DecodeStatus::kUnknownReturnMode;
  product = static_cast<ProductId>(p[kProductIdOffset]);
  if (sensor_model(product) == nullptr) return DecodeStatus::kUnknownProduct;
  return DecodeStatus::kOk;
}

PacketDecoder::PacketDecoder(Calibration calibration, DecoderConfig config)
    : calibration_(std::move(calibration)), config_(config) {
  min_range_m_ = static_cast<float>(config_.min_range_m);
  max_range_m_ = static_cast<float>(config_.max_range_m);
  (void)azimuth_table();  // build now, not on the first packet
}

bool PacketDecoder::lock_model(ProductId product) noexcept {
  const SensorModel* model = sensor_model(product);
  if (model == nullptr) return false;
  if (config_.expected_product != ProductId::kUnknown && product != config_.expected_product) {
    return false;
  }
  if (calibration_.lasers.empty()) calibration_ = builtin_calibration(product);
  if (calibration_.lasers.size() != model->laser_count) return false;
  const auto rings = rings_by_elevation(calibration_);
  distance_resolution_m_ = static_cast<float>(calibration_.distance_resolution_m > 0.0
                                                  ? calibration_.distance_resolution_m
                                                  : model->distance_resolution_m);
  for (std::size_t c = 0; c < kChannelsPerBlock; ++c) {
    const std::uint8_t laser = model->laser_of_channel[c];
    const LaserCorrection& l = calibration_.lasers[laser];
    ChannelTable& t = channels_[c];
    t.cos_rot = static_cast<float>(std::cos(l.rot_correction_rad));
    t.sin_rot = static_cast<float>(std::sin(l.rot_correction_rad));
    t.rot_cdeg = static_cast<float>(l.rot_correction_rad * 18000.0 / std::numbers::pi);
    t.cos_vert = static_cast<float>(std::cos(l.vert_correction_rad));
    t.sin_vert = static_cast<float>(std::sin(l.vert_correction_rad));
    t.dist_correction_m = static_cast<float>(l.dist_correction_m);
    t.vert_offset_m = static_cast<float>(l.vert_offset_m);
    t.horiz_offset_m = static_cast<float>(l.horiz_offset_m);
    t.offset_ns = model->channel_offset_ns[c];
    t.fraction_of_firing = static_cast<float>(model->channel_offset_ns[c]) /
                           static_cast<float>(model->block_period_ns);
    t.laser = laser;
    t.ring = static_cast<std::uint8_t>(rings[laser]);
  }
  model_ = model;
  product_ = product;
  return true;
}

DecodeStatus PacketDecoder::decode(std::span<const std::byte> payload,
                                   DecodedPacket& out) noexcept {
  ProductId product = ProductId::kUnknown;
  ReturnMode mode = ReturnMode::kStrongest;
  const DecodeStatus header = peek_data_packet(payload, product, mode);
  switch (header) {
    case DecodeStatus::kOk:
      break;
    case DecodeStatus::kWrongSize:
      ++counters_.wrong_size;
      return header;
    case DecodeStatus::kBadBlockFlag:
      ++counters_.bad_block_flag;
      return header;
    case DecodeStatus::kBadAzimuth:
      ++counters_.bad_azimuth;
      return header;
    case DecodeStatus::kUnknownReturnMode:
      ++counters_.unknown_return_mode;
      return header;
    default:
      ++counters_.unknown_product;
      return DecodeStatus::kUnknownProduct;
  }
  if (product != product_ && (product_ != ProductId::kUnknown || !lock_model(product))) {
    ++counters_.model_mismatch;
    return DecodeStatus::kModelMismatch;
  }

  const std::byte* p = payload.data();
  const bool dual = mode == ReturnMode::kDual;
  const std::uint32_t blocks_per_firing = dual ? 2 : 1;
  const std::uint32_t firings = static_cast<std::uint32_t>(kBlocksPerPacket) / blocks_per_firing;

  out.product = product;
  out.return_mode = mode;
  out.device_time_us = read_u32_le(p + kTimestampOffset);
  out.firing_count = firings;
  out.firing_period_ns = model_->block_period_ns;
  for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
    out.block_azimuth_cdeg[b] = read_u16_le(p + b * kBlockBytes + 2);
  }

  // Rotation during each firing, from the next firing's azimuth; the last firing borrows its
  // predecessor's (manual 9.6: "use the azimuth gap of the previous block").
  std::array<std::uint32_t, kBlocksPerPacket> gap_cdeg{};
  std::uint32_t fallback_gap = 0, gap_sum = 0, gap_n = 0;
  for (std::uint32_t f = 0; f + 1 < firings; ++f) {
    const std::uint32_t a = out.block_azimuth_cdeg[f * blocks_per_firing];
    const std::uint32_t b = out.block_azimuth_cdeg[(f + 1) * blocks_per_firing];
    const std::uint32_t gap = (b + kFullTurnCdeg - a) % kFullTurnCdeg;
    if (gap <= kMaxFiringGapCdeg) {
      gap_cdeg[f] = gap;
      fallback_gap = gap;
      gap_sum += gap;
      ++gap_n;
    } else {
      gap_cdeg[f] = kFullTurnCdeg;  // marks "not measurable"
    }
  }
  gap_cdeg[firings - 1] = kFullTurnCdeg;
  for (std::uint32_t f = 0; f < firings; ++f) {
    if (gap_cdeg[f] == kFullTurnCdeg)
      gap_cdeg[f] = f > 0 && gap_cdeg[f - 1] <= kMaxFiringGapCdeg ? gap_cdeg[f - 1] : fallback_gap;
  }
  out.rpm = gap_n == 0 ? 0.f
                       : static_cast<float>(static_cast<double>(gap_sum) / gap_n / 36000.0 /
                                            (model_->block_period_ns * 1e-9) * 60.0);

  const AzimuthTable& table = azimuth_table();
  std::uint32_t n = 0, no_return = 0, out_of_range = 0, duplicates = 0;
  for (std::uint32_t b = 0; b < kBlocksPerPacket; ++b) {
    const std::byte* block = p + b * kBlockBytes;
    const std::uint32_t firing = b / blocks_per_firing;
    const std::uint16_t az = out.block_azimuth_cdeg[b];
    const std::uint32_t az_index = az == kFullTurnCdeg ? 0 : az;
    const float ca = table.cos_v[az_index], sa = table.sin_v[az_index];
    const float gap = static_cast<float>(gap_cdeg[firing]);
    const float gap_rad = gap * kCdegToRad;
    const std::int32_t firing_ns = static_cast<std::int32_t>(firing) * model_->block_period_ns;
    const bool second_return = dual && (b % 2 == 1);
    const std::byte* partner = second_return ? block - kBlockBytes : nullptr;
    for (std::uint32_t c = 0; c < kChannelsPerBlock; ++c) {
      const std::byte* ch = block + 4 + c * kChannelBytes;
      const std::uint16_t raw = read_u16_le(ch);
      if (raw == 0) {
        ++no_return;
        continue;
      }
      // Dual mode: the sensor repeats a single return in both blocks (manual 9.3.1.5).
      if (partner != nullptr && read_u16_le(partner + 4 + c * kChannelBytes) == raw) {
        ++duplicates;
        continue;
      }
      const ChannelTable& t = channels_[c];
      const float range = static_cast<float>(raw) * distance_resolution_m_ + t.dist_correction_m;
      if (range < min_range_m_ || range > max_range_m_) {
        ++out_of_range;
        continue;
      }
      // Rotation since the block's first firing, small (< 1°): third-order Taylor is exact to
      // ~1e-9, far cheaper than sin/cos per point.
      const float i = gap_rad * t.fraction_of_firing;
      const float ci = 1.f - 0.5f * i * i;
      const float si = i - i * i * i * (1.f / 6.f);
      const float c_ai = ca * ci - sa * si;  // cos(a + i)
      const float s_ai = sa * ci + ca * si;  // sin(a + i)
      // θ = a + i − rot_correction
      const float cos_t = c_ai * t.cos_rot + s_ai * t.sin_rot;
      const float sin_t = s_ai * t.cos_rot - c_ai * t.sin_rot;
      const float xy = range * t.cos_vert - t.vert_offset_m * t.sin_vert;
      DecodedPoint& pt = out.points[n++];
      // Velodyne azimuth is clockwise seen from above with 0 along the connector-facing-back
      // axis; x forward, y left means y = −xy·sin θ (ros-drivers velodyne_pointcloud rawdata.cc).
      pt.x_m = xy * cos_t + t.horiz_offset_m * sin_t;
      pt.y_m = -xy * sin_t + t.horiz_offset_m * cos_t;
      pt.z_m = range * t.sin_vert + t.vert_offset_m * t.cos_vert;
      pt.range_m = range;
      pt.t_ns = firing_ns + t.offset_ns;
      float az_cdeg = static_cast<float>(az) + gap * t.fraction_of_firing - t.rot_cdeg;
      if (az_cdeg < 0.f) az_cdeg += static_cast<float>(kFullTurnCdeg);
      if (az_cdeg >= static_cast<float>(kFullTurnCdeg))
        az_cdeg -= static_cast<float>(kFullTurnCdeg);
      std::uint32_t az_rounded = static_cast<std::uint32_t>(az_cdeg + 0.5f);
      pt.azimuth_cdeg = static_cast<std::uint16_t>(az_rounded >= kFullTurnCdeg ? 0 : az_rounded);
      pt.intensity = static_cast<std::uint8_t>(ch[2]);
      pt.block = static_cast<std::uint8_t>(b);
      pt.channel = static_cast<std::uint8_t>(c);
      pt.laser = t.laser;
      pt.ring = t.ring;
      pt.return_index = second_return ? 1 : 0;
    }
  }
  out.point_count = n;
  out.no_return_count = no_return;
  out.out_of_range_count = out_of_range;
  out.dual_duplicate_count = duplicates;
  ++counters_.packets_ok;
  counters_.points += n;
  return DecodeStatus::kOk;
}

}  // namespace posed::drivers::velodyne
