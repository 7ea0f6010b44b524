#include "drivers/camera/d4xx_metadata_writer.hpp"

#include <cmath>

#include "drivers/camera/d4xx_metadata.hpp"

namespace posed::drivers::camera {
namespace {

/// librealsense's md_type for md_capture_stats (the parser skips the block by its size).
constexpr std::uint32_t kMdCaptureStatsId = 0x00000003u;

struct LittleEndian {
  std::vector<std::byte>& v;
  void u8(std::uint32_t x) { v.push_back(static_cast<std::byte>(x & 0xFF)); }
  void u16(std::uint32_t x) { u8(x), u8(x >> 8); }
  void u32(std::uint32_t x) { u16(x & 0xFFFF), u16(x >> 16); }
  void u64(std::uint64_t x) {
    u32(static_cast<std::uint32_t>(x)), u32(static_cast<std::uint32_t>(x >> 32));
  }
  void zeros(std::size_t n) { v.insert(v.end(), n, std::byte{0}); }
};

void capture_timing(LittleEndian& b, const D4xxFrameFacts& f) {
  b.u32(kMdCaptureTimingId);
  b.u32(40);
  b.u32(1);     // version
  b.u32(0x3F);  // flags: every field below valid
  b.u32(f.frame_counter);
  b.u32(f.sensor_timestamp_us);
  b.u32(f.frame_interval_us / 2);  // readout_time: half a frame, as the arrival model assumes
  b.u32(f.exposure_time_us);
  b.u32(f.frame_interval_us);
  b.u32(0);  // pipe_latency
}

void capture_stats(LittleEndian& b, const D4xxFrameFacts& f) {
  b.u32(kMdCaptureStatsId);
  b.u32(80);
  b.u32(0x401);  // flags: exposure_time and sensor_framerate valid
  b.u32(0);      // reserved
  b.u64(f.exposure_time_us);
  b.u64(0);        // exposure_compensation_flags
  b.zeros(8 * 4);  // compensation value, iso, focus, lens, white balance, flash, power, zoom
  b.u64(0);        // scene_mode
  b.u64(f.fps);    // sensor_framerate
}

void configuration(LittleEndian& b, const D4xxFrameFacts& f) {
  b.u32(kMdConfigurationId);
  b.u32(40);
  b.u32(3);      // version
  b.u32(0x1FF);  // flags
  b.u8(2);       // hw_type
  b.u8(7);       // sku_id (D435i)
  b.u32(0);      // cookie
  // format: a firmware code that neither librealsense nor posed reads (the V4L2 node's format
  // says what the bytes are); colour and depth differ
  b.u16(f.node == D4xxNode::kDepth ? 0x01 : 0x04);
  b.u16(f.width_px);
  b.u16(f.height_px);
  b.u16(f.fps);
  b.u16(0);  // trigger: free running
  b.u16(1);  // calibration_count
  b.zeros(6);
}

void rgb_control(LittleEndian& b, const D4xxFrameFacts& f) {
  // version, flags, brightness, contrast, saturation, sharpness, ae_mode, awb_temp, gain,
  // backlight_comp, gamma, hue, manual_exp [100 us], manual_wb, power_line_frequency,
  // low_light_comp
  b.u32(kMdRgbControlId);
  b.u32(72);
  const std::uint32_t rgb[16] = {
      2, 0x3FFF, 0, 50, 64, 50, 1, 4600, f.gain, 0, 300, 0, f.exposure_time_us / 100, 4600, 1, 0};
  for (const std::uint32_t x : rgb) b.u32(x);
}

void depth_control(LittleEndian& b, const D4xxFrameFacts& f) {
  // version, flags (gain, exposure, laser power, ae mode, priority, roi, preset), manual_gain,
  // manual_exposure [us], laser_power [mW], auto_exposure_mode, exposure_priority, the
  // auto-exposure ROI (left, right, top, bottom) [px], preset, laser power mode (1 = on)
  b.u32(kMdDepthControlId);
  b.u32(60);
  const std::uint32_t roi_left = f.width_px / 8u, roi_right = f.width_px - f.width_px / 8u;
  const std::uint32_t roi_top = f.height_px / 8u, roi_bottom = f.height_px - f.height_px / 8u;
  const std::uint32_t depth[13] = {1,          0x7F, f.gain,   f.exposure_time_us, f.laser_power_mw,
                                   1,          1,    roi_left, roi_right,          roi_top,
                                   roi_bottom, 0,    1};
  for (const std::uint32_t x : depth) b.u32(x);
}

}  // namespace

void set_usb_arrival(D4xxFrameFacts& f, std::int64_t arrival_ns) {
  f.host_sof_ns = static_cast<std::uint64_t>(
      arrival_ns - std::llround(static_cast<double>(f.frame_interval_us) * 500.0));
  f.usb_sof = static_cast<std::uint16_t>((f.host_sof_ns / 1'000'000) & 0x7FF);
}

void encode_d4xx_metadata(const D4xxFrameFacts& f, std::vector<std::byte>& out) {
  out.clear();
  LittleEndian b{out};
  b.u64(f.host_sof_ns);
  b.u16(f.usb_sof & 0x7FF);
  const std::size_t length_at = out.size();
  b.u8(0);                   // bHeaderLength, set below
  b.u8(0x80 | 0x08 | 0x04);  // bmHeaderInfo: EOH, SCR, PTS (UVC 1.5 table 2-6)
  b.u32(f.pts_us);
  b.u32(f.sensor_timestamp_us);  // SCR source clock: the same device clock
  b.u16(f.usb_sof & 0x7FF);
  capture_timing(b, f);
  if (f.node == D4xxNode::kDepth) {
    capture_stats(b, f);
    depth_control(b, f);
    configuration(b, f);
  } else {
    configuration(b, f);
    rgb_control(b, f);
  }
  // bHeaderLength is one byte: the depth layout's 232 bytes are the largest that fits.
  out[length_at] = static_cast<std::byte>(out.size() - kUvcMetaBufPrefixBytes);
}

}  // namespace posed::drivers::camera
