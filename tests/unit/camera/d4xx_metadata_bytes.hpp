#pragma once
// Byte builders for D4xx frame metadata as a D435i delivers it on the uvcvideo metadata node,
// field by field from librealsense src/metadata.h and linux/uvcvideo.h (struct uvc_meta_buf).
// Shared by the parser tests and the fake metadata node.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "drivers/camera/d4xx_metadata.hpp"

namespace posed::test {

using drivers::camera::kMdCaptureTimingId;
using drivers::camera::kMdConfigurationId;
using drivers::camera::kMdDepthControlId;
using drivers::camera::kMdRgbControlId;
using drivers::camera::kUvcMetaBufPrefixBytes;

struct Bytes {
  std::vector<std::byte> v;
  void u8(std::uint32_t x) { v.push_back(static_cast<std::byte>(x & 0xFF)); }
  void u16(std::uint32_t x) { u8(x), u8(x >> 8); }
  void u32(std::uint32_t x) { u16(x & 0xFFFF), u16(x >> 16); }
  void u64(std::uint64_t x) {
    u32(static_cast<std::uint32_t>(x)), u32(static_cast<std::uint32_t>(x >> 32));
  }
  void zeros(std::size_t n) { v.insert(v.end(), n, std::byte{0}); }
};

/// A depth frame's metadata: uvc_meta_buf + UVC header (PTS, SCR) + md_depth_y_normal_mode
/// (capture_timing, capture_stats, depth_control, configuration).
inline Bytes depth_metadata(std::uint32_t md_size_convention_extra,
                            std::uint32_t frame_counter = 4242,
                            std::uint32_t sensor_timestamp_us = 0xFFFFFF00) {
  Bytes b;
  b.u64(123'456'789'000);  // ns
  b.u16(0x2A5);            // sof
  const std::size_t len_at = b.v.size();
  b.u8(0);                   // bHeaderLength, patched below
  b.u8(0x8C | 0x02 | 0x01);  // EOH, SCR, PTS, EOF, FID
  b.u32(0x89ABCDEF);         // PTS [us]
  b.u32(0x01020304);         // SCR STC
  b.u16(0x0456);             // SCR SOF
  // md_capture_timing
  b.u32(kMdCaptureTimingId);
  b.u32(32 + md_size_convention_extra);
  b.u32(1);     // version
  b.u32(0x3F);  // flags
  b.u32(frame_counter);
  b.u32(sensor_timestamp_us);  // default near the 2^32 wrap
  b.u32(15000);                // readout_time
  b.u32(8250);                 // exposure_time
  b.u32(33333);                // frame_interval
  b.u32(900);                  // pipe_latency
  // md_capture_stats: header + 72 bytes we skip (flags, reserved, u64 exposure, u64 compensation
  // flags, 8 x u32, u64 scene_mode, u64 sensor_framerate)
  b.u32(0x00000003);
  b.u32(72 + md_size_convention_extra);
  b.zeros(72);
  // md_depth_control
  b.u32(kMdDepthControlId);
  b.u32(52 + md_size_convention_extra);
  b.u32(1);        // version
  b.u32(0x7F);     // flags
  b.u32(16);       // manual_gain
  b.u32(33000);    // manual_exposure
  b.u32(150);      // laser_power
  b.u32(1);        // auto_exposure_mode
  b.zeros(7 * 4);  // priority, roi x4, preset, laserPowerMode
  // md_configuration
  b.u32(kMdConfigurationId);
  b.u32(32 + md_size_convention_extra);
  b.u32(3);      // version
  b.u32(0x1FF);  // flags
  b.u8(2);       // hw_type
  b.u8(7);       // sku_id
  b.u32(0);      // cookie
  b.u16(0x0B);   // format
  b.u16(848);    // width
  b.u16(480);    // height
  b.u16(30);     // fps
  b.u16(0);      // trigger
  b.u16(5);      // calibration_count
  b.zeros(6);
  b.v[len_at] = static_cast<std::byte>(b.v.size() - kUvcMetaBufPrefixBytes);
  return b;
}

}  // namespace posed::test
