#pragma once
// Per-frame metadata of the RealSense D4xx (D435i) as the Linux uvcvideo driver delivers it on
// the video node's companion metadata node (V4L2_BUF_TYPE_META_CAPTURE, V4L2_META_FMT_UVC
// 'UVCH'; Intel's patched kernels call the same layout 'D4XX'). Pure parsing, never throws.
//
// Layout (little-endian, packed):
//   struct uvc_meta_buf (linux/uvcvideo.h): u64 ns (host CLOCK_MONOTONIC at the frame's first
//   USB packet), u16 sof (USB frame number), then the UVC payload header itself: u8
//   bHeaderLength, u8 bmHeaderInfo, [u32 dwPresentationTime if bit 2 (PTS)], [u32 STC + u16 SOF
//   if bit 3 (SCR)] (UVC 1.5, 2.4.3.3), then Intel's metadata blocks up to bHeaderLength.
//   Each Intel block starts with md_header {u32 md_type_id, u32 md_size}; the blocks
//   (librealsense src/metadata.h):
//     md_capture_timing (0x80000001): version, flags, frame_counter, sensor_timestamp [us],
//       readout_time [us], exposure_time [us], frame_interval [us], pipe_latency [us]
//     md_configuration (0x80000002): version, flags, u8 hw_type, u8 sku_id, u32 cookie,
//       u16 format, width, height, fps, trigger, calibration_count, u8 reserved[6]
//     md_depth_control (0x80000000): version, flags, manual_gain, manual_exposure (firmware
//       units), laser_power, auto_exposure_mode, ...
//     md_rgb_control (0x80000005): version, flags, brightness, contrast, saturation, sharpness,
//       ae_mode, awb_temp, gain, backlight_comp, gamma, hue, manual_exp, manual_wb, ...
//     md_capture_stats (0x00000003): skipped here.
// librealsense reads the frame's hardware timestamp from the UVC PTS (dwPresentationTime, the
// device's 1 MHz clock, 32 bits) and "sensor_timestamp" (middle of exposure, µs) from
// md_capture_timing; both wrap at 2^32 µs (~71.6 min), so ClockSync unwraps them.

#include <cstdint>
#include <span>
#include <string_view>

namespace posed::drivers::camera {

enum class MetadataStatus : std::uint8_t {
  kOk,
  kTooShort,       ///< shorter than the uvc_meta_buf header or its own bHeaderLength
  kNoIntelBlocks,  ///< a valid UVC header without D4xx blocks (metadata not enabled in firmware)
  kMalformed,      ///< a block header runs past the end
};
std::string_view to_string(MetadataStatus s);

struct D4xxFrameMetadata {
  std::uint64_t host_sof_ns = 0;  ///< uvc_meta_buf.ns: host CLOCK_MONOTONIC at SOF [ns]
  std::uint16_t usb_sof = 0;      ///< USB frame number (1 kHz, 11 bits) at SOF
  bool has_pts = false;
  std::uint32_t pts_us = 0;  ///< UVC dwPresentationTime: device clock [us], wraps 2^32
  bool has_scr = false;
  std::uint32_t scr_stc_us = 0;  ///< UVC SCR source time clock [us]
  std::uint16_t scr_sof = 0;     ///< UVC SCR SOF token counter

  bool has_capture_timing = false;
  std::uint32_t frame_counter = 0;         ///< md_capture_timing.frame_counter
  std::uint32_t sensor_timestamp_us = 0;   ///< md_capture_timing.sensor_timestamp [us]
  std::uint32_t readout_time_us = 0;       ///< [us]
  std::uint32_t exposure_time_us = 0;      ///< md_capture_timing.exposure_time [us]
  std::uint32_t frame_interval_us = 0;     ///< [us]
  std::uint32_t pipe_latency_us = 0;       ///< [us]
  std::uint32_t capture_timing_flags = 0;  ///< which of the above are valid (bit order as listed)

  bool has_configuration = false;
  std::uint16_t width_px = 0;   ///< md_configuration.width [px]
  std::uint16_t height_px = 0;  ///< md_configuration.height [px]
  std::uint16_t fps = 0;        ///< md_configuration.fps [Hz]
  std::uint16_t format = 0;     ///< md_configuration.format (firmware format code)
  std::uint16_t calibration_count = 0;

  bool has_gain = false;
  std::uint32_t gain = 0;  ///< depth manual_gain or rgb gain (firmware units)
  bool has_control_exposure = false;
  std::uint32_t control_exposure = 0;    ///< depth manual_exposure / rgb manual_exp (fw units)
  std::uint32_t auto_exposure_mode = 0;  ///< 1 = auto exposure on
  std::uint32_t laser_power = 0;         ///< depth only [mW, firmware units]
};

/// Block ids (librealsense md_type).
inline constexpr std::uint32_t kMdDepthControlId = 0x80000000u;
inline constexpr std::uint32_t kMdCaptureTimingId = 0x80000001u;
inline constexpr std::uint32_t kMdConfigurationId = 0x80000002u;
inline constexpr std::uint32_t kMdRgbControlId = 0x80000005u;
/// sizeof(uvc_meta_buf) without the payload header: u64 ns + u16 sof
inline constexpr std::size_t kUvcMetaBufPrefixBytes = 10;

MetadataStatus parse_d4xx_metadata(std::span<const std::byte> bytes, D4xxFrameMetadata& out);

}  // namespace posed::drivers::camera
