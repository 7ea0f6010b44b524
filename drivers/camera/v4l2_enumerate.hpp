#pragma once
// What a V4L2 node offers, for `posectl inspect camera --list`: VIDIOC_QUERYCAP, then
// VIDIOC_ENUM_FMT, VIDIOC_ENUM_FRAMESIZES and VIDIOC_ENUM_FRAMEINTERVALS per format, through
// V4l2Device so a fake can answer.

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/camera/v4l2_device.hpp"

namespace posed::drivers::camera {

struct V4l2FrameSize {
  std::uint32_t width = 0, height = 0;  ///< [px]; for stepwise sizes the largest
  bool stepwise = false;                ///< a range (min..max) rather than one size
  std::vector<double> rates_hz;         ///< discrete frame rates [Hz]; empty when not listed
};

struct V4l2FormatInfo {
  std::uint32_t fourcc = 0;
  std::string description;
  std::vector<V4l2FrameSize> sizes;  ///< empty for metadata formats
};

struct V4l2NodeInfo {
  std::string path;
  std::string driver, card, bus_info;
  bool video_capture = false;  ///< V4L2_CAP_VIDEO_CAPTURE
  bool meta_capture = false;   ///< V4L2_CAP_META_CAPTURE (uvcvideo metadata node)
  std::vector<V4l2FormatInfo> formats;
};

/// The /dev/video* nodes in `dev_dir`, in numeric order.
std::vector<std::string> list_v4l2_nodes(const std::string& dev_dir = "/dev");

/// Queries one node. false with `error` (path and the ioctl) when it cannot be opened or is not
/// a V4L2 device.
bool query_v4l2_node(V4l2Device& device, const std::string& path, V4l2NodeInfo& out,
                     std::string& error);

}  // namespace posed::drivers::camera
