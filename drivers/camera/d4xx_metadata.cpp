#include "drivers/camera/d4xx_metadata.hpp"

#include <cstring>

namespace posed::drivers::camera {
namespace {

template <class T>
T le(std::span<const std::byte> b, std::size_t at) {
  T v{};
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    v = static_cast<T>(v | (static_cast<T>(static_cast<std::uint8_t>(b[at + i])) << (8 * i)));
  }
  return v;
}

// Struct sizes including md_header (librealsense src/metadata.h, #pragma pack(1)). Walking by
// these instead of md_size keeps parsing right whether firmware counts the header in md_size.
std::size_t known_block_bytes(std::uint32_t id) {
  switch (id) {
    case kMdCaptureTimingId:
      return 8 + 8 * 4;  // md_capture_timing: 40
    case kMdConfigurationId:
      return 8 + 4 + 4 + 1 + 1 + 4 + 6 * 2 + 6;  // md_configuration: 40
    case kMdDepthControlId:
      return 8 + 13 * 4;  // md_depth_control: 60
    case kMdRgbControlId:
      return 8 + 16 * 4;  // md_rgb_control: 72
    case 0x00000003u:
      return 8 + 4 + 4 + 8 + 8 + 8 * 4 + 8 + 8;  // md_capture_stats: 80
    default:
      return 0;
  }
}

}  // namespace

std::string_view to_string(MetadataStatus s) {
  switch (s) {
    case MetadataStatus::kOk:
      return "ok";
    case MetadataStatus::kTooShort:
      return "too_short";
    case MetadataStatus::kNoIntelBlocks:
      return "no_intel_blocks";
    case MetadataStatus::kMalformed:
      return "malformed";
  }
  return "unknown";
}

MetadataStatus parse_d4xx_metadata(std::span<const std::byte> b, D4xxFrameMetadata& out) {
  out = {};
  if (b.size() < kUvcMetaBufPrefixBytes + 2) return MetadataStatus::kTooShort;
  out.host_sof_ns = le<std::uint64_t>(b, 0);
  out.usb_sof = le<std::uint16_t>(b, 8);
  const std::size_t header_len = static_cast<std::uint8_t>(b[10]);
  const auto info = static_cast<std::uint8_t>(b[11]);
  const std::size_t end = kUvcMetaBufPrefixBytes + header_len;
  if (header_len < 2 || end > b.size()) return MetadataStatus::kTooShort;
  std::size_t at = kUvcMetaBufPrefixBytes + 2;
  if ((info & 0x04) != 0) {  // UVC bmHeaderInfo bit 2: PTS present
    if (at + 4 > end) return MetadataStatus::kTooShort;
    out.has_pts = true;
    out.pts_us = le<std::uint32_t>(b, at);
    at += 4;
  }
  if ((info & 0x08) != 0) {  // bit 3: SCR present
    if (at + 6 > end) return MetadataStatus::kTooShort;
    out.has_scr = true;
    out.scr_stc_us = le<std::uint32_t>(b, at);
    out.scr_sof = le<std::uint16_t>(b, at + 4);
    at += 6;
  }
  bool any = false;
  while (at + 8 <= end) {
    const std::uint32_t id = le<std::uint32_t>(b, at);
    const std::uint32_t md_size = le<std::uint32_t>(b, at + 4);
    std::size_t len = known_block_bytes(id);
    if (len == 0) len = md_size;  // unknown block: trust its size
    if (len < 8 || at + len > end) return MetadataStatus::kMalformed;
    const std::size_t p = at + 8;  // first field after md_header
    switch (id) {
      case kMdCaptureTimingId:
        out.has_capture_timing = true;
        out.capture_timing_flags = le<std::uint32_t>(b, p + 4);
        out.frame_counter = le<std::uint32_t>(b, p + 8);
        out.sensor_timestamp_us = le<std::uint32_t>(b, p + 12);
        out.readout_time_us = le<std::uint32_t>(b, p + 16);
        out.exposure_time_us = le<std::uint32_t>(b, p + 20);
        out.frame_interval_us = le<std::uint32_t>(b, p + 24);
        out.pipe_latency_us = le<std::uint32_t>(b, p + 28);
        break;
      case kMdConfigurationId:
        out.has_configuration = true;
        // version, flags, u8 hw_type, u8 sku_id, u32 cookie: format starts 14 bytes in
        out.format = le<std::uint16_t>(b, p + 14);
        out.width_px = le<std::uint16_t>(b, p + 16);
        out.height_px = le<std::uint16_t>(b, p + 18);
        out.fps = le<std::uint16_t>(b, p + 20);
        out.calibration_count = le<std::uint16_t>(b, p + 24);
        break;
      case kMdDepthControlId:
        out.has_gain = out.has_control_exposure = true;
        out.gain = le<std::uint32_t>(b, p + 8);
        out.control_exposure = le<std::uint32_t>(b, p + 12);
        out.laser_power = le<std::uint32_t>(b, p + 16);
        out.auto_exposure_mode = le<std::uint32_t>(b, p + 20);
        break;
      case kMdRgbControlId:
        out.has_gain = out.has_control_exposure = true;
        // version, flags, brightness, contrast, saturation, sharpness, ae_mode, awb_temp, gain,
        // backlight_comp, gamma, hue, manual_exp (then manual_wb, power_line_frequency, ...)
        out.auto_exposure_mode = le<std::uint32_t>(b, p + 24);
        out.gain = le<std::uint32_t>(b, p + 32);
        out.control_exposure = le<std::uint32_t>(b, p + 48);
        break;
      default:
        break;
    }
    any = true;
    at += len;
  }
  return any ? MetadataStatus::kOk : MetadataStatus::kNoIntelBlocks;
}

}  // namespace posed::drivers::camera
