#pragma once
// The D435i's per-frame metadata as the uvcvideo metadata node delivers it, written: for the
// simulator (tools/sim) and for tests that need real metadata buffers. The exact layout
// drivers/camera/d4xx_metadata.hpp parses (struct uvc_meta_buf of linux/uvcvideo.h, the UVC payload
// header with PTS and SCR, then librealsense's metadata blocks, #pragma pack(1), md_size counting
// the md_header as firmware does). The colour node sends md_capture_timing, md_configuration and
// md_rgb_control; the depth node librealsense's md_depth_y_normal_mode: md_capture_timing,
// md_capture_stats, md_depth_control (gain, exposure, laser power) and md_configuration.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace posed::drivers::camera {

/// Which of the D435i's UVC nodes sent the frame.
enum class D4xxNode : std::uint8_t {
  kColour,  ///< RGB sensor (YUYV)
  kDepth,   ///< stereo depth (Z16)
};

struct D4xxFrameFacts {
  D4xxNode node = D4xxNode::kColour;
  std::uint64_t host_sof_ns = 0;          ///< uvc_meta_buf.ns: host time of the first packet [ns]
  std::uint16_t usb_sof = 0;              ///< USB frame number (11 bits)
  std::uint32_t frame_counter = 0;        ///< frames since streaming started [1]
  std::uint32_t sensor_timestamp_us = 0;  ///< exposure midpoint on the device clock [us], wraps
  std::uint32_t pts_us = 0;               ///< start of exposure on the device clock [us], wraps
  std::uint32_t exposure_time_us = 0;     ///< [us]
  std::uint32_t frame_interval_us = 0;    ///< [us]
  /// colour: md_rgb_control.gain (64 = 1x); depth: md_depth_control.manual_gain (16 = 1x)
  std::uint32_t gain = 64;
  std::uint32_t laser_power_mw = 150;  ///< depth only: IR projector power [mW]
  std::uint16_t width_px = 640;
  std::uint16_t height_px = 480;
  std::uint16_t fps = 15;  ///< [Hz]
};

/// Sets host_sof_ns and usb_sof for a frame whose last USB packet reached the host at
/// `arrival_ns`: its first packet left about half a frame interval earlier.
void set_usb_arrival(D4xxFrameFacts& facts, std::int64_t arrival_ns);

/// Replaces `out` with the metadata buffer of one frame.
void encode_d4xx_metadata(const D4xxFrameFacts& facts, std::vector<std::byte>& out);

}  // namespace posed::drivers::camera
