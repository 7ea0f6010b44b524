#pragma once
// The D435i colour node's per-frame metadata as the uvcvideo metadata node delivers it, for the
// simulator: the exact layout drivers/camera/d4xx_metadata.hpp parses (struct uvc_meta_buf of
// linux/uvcvideo.h, the UVC payload header with PTS and SCR, then librealsense's
// md_capture_timing, md_configuration and md_rgb_control blocks, #pragma pack(1), md_size
// counting the md_header as firmware does).

#include <cstddef>
#include <cstdint>
#include <vector>

namespace posed::sim {

struct D4xxFrameFacts {
  std::uint64_t host_sof_ns = 0;          ///< uvc_meta_buf.ns: host time of the first packet [ns]
  std::uint16_t usb_sof = 0;              ///< USB frame number (11 bits)
  std::uint32_t frame_counter = 0;        ///< frames since streaming started [1]
  std::uint32_t sensor_timestamp_us = 0;  ///< exposure midpoint on the device clock [us], wraps
  std::uint32_t pts_us = 0;               ///< start of exposure on the device clock [us], wraps
  std::uint32_t exposure_time_us = 0;     ///< [us]
  std::uint32_t frame_interval_us = 0;    ///< [us]
  std::uint32_t gain = 64;                ///< rgb gain, firmware units (64 = 1x)
  std::uint16_t width_px = 640;
  std::uint16_t height_px = 480;
  std::uint16_t fps = 15;  ///< [Hz]
};

/// Replaces `out` with the metadata buffer of one frame.
void encode_d4xx_metadata(const D4xxFrameFacts& facts, std::vector<std::byte>& out);

}  // namespace posed::sim
