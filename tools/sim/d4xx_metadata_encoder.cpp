#include "tools/sim/d4xx_metadata_encoder.hpp"

#include "drivers/camera/d4xx_metadata.hpp"

namespace posed::sim {
namespace {

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

}  // namespace

void encode_d4xx_metadata(const D4xxFrameFacts& f, std::vector<std::byte>& out) {
  namespace cam = drivers::camera;
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
  // md_capture_timing
  b.u32(cam::kMdCaptureTimingId);
  b.u32(40);
  b.u32(1);     // version
  b.u32(0x3F);  // flags: every field below valid
  b.u32(f.frame_counter);
  b.u32(f.sensor_timestamp_us);
  b.u32(f.frame_interval_us / 2);  // readout_time: a rolling shutter reads for half a frame
  b.u32(f.exposure_time_us);
  b.u32(f.frame_interval_us);
  b.u32(0);  // pipe_latency
  // md_configuration
  b.u32(cam::kMdConfigurationId);
  b.u32(40);
  b.u32(3);      // version
  b.u32(0x1FF);  // flags
  b.u8(2);       // hw_type
  b.u8(7);       // sku_id (D435i)
  b.u32(0);      // cookie
  b.u16(0x04);   // format: YUYV
  b.u16(f.width_px);
  b.u16(f.height_px);
  b.u16(f.fps);
  b.u16(0);  // trigger
  b.u16(1);  // calibration_count
  b.zeros(6);
  // md_rgb_control: version, flags, brightness, contrast, saturation, sharpness, ae_mode,
  // awb_temp, gain, backlight_comp, gamma, hue, manual_exp [100 us], manual_wb,
  // power_line_frequency, low_light_comp
  b.u32(cam::kMdRgbControlId);
  b.u32(72);
  const std::uint32_t rgb[16] = {
      2, 0x3FFF, 0, 50, 64, 50, 1, 4600, f.gain, 0, 300, 0, f.exposure_time_us / 100, 4600, 1, 0};
  for (const std::uint32_t x : rgb) b.u32(x);
  out[length_at] = static_cast<std::byte>(out.size() - cam::kUvcMetaBufPrefixBytes);
}

}  // namespace posed::sim
