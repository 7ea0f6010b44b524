#include "drivers/camera/v4l2_enumerate.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

namespace posed::drivers::camera {
namespace {

std::string cstr(const std::uint8_t* s, std::size_t n) {
  const auto* c = reinterpret_cast<const char*>(s);
  return std::string(c, strnlen(c, n));
}

std::vector<double> rates(V4l2Device& dev, int fd, std::uint32_t fourcc, std::uint32_t w,
                          std::uint32_t h) {
  std::vector<double> out;
  for (std::uint32_t i = 0; i < 64; ++i) {
    v4l2_frmivalenum iv{};
    iv.index = i;
    iv.pixel_format = fourcc;
    iv.width = w;
    iv.height = h;
    if (dev.ioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &iv) != 0) break;
    if (iv.type != V4L2_FRMIVAL_TYPE_DISCRETE) {
      // Continuous/stepwise: report the fastest rate only.
      if (iv.stepwise.min.numerator != 0) {
        out.push_back(double(iv.stepwise.min.denominator) / iv.stepwise.min.numerator);
      }
      break;
    }
    if (iv.discrete.numerator != 0) {
      out.push_back(double(iv.discrete.denominator) / iv.discrete.numerator);
    }
  }
  return out;
}

}  // namespace

std::vector<std::string> list_v4l2_nodes(const std::string& dev_dir) {
  std::vector<std::pair<int, std::string>> found;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dev_dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("video", 0) != 0 || name.size() == 5) continue;
    if (!std::all_of(name.begin() + 5, name.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      continue;
    }
    found.emplace_back(std::stoi(name.substr(5)), e.path().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> out;
  for (auto& f : found) out.push_back(std::move(f.second));
  return out;
}

bool query_v4l2_node(V4l2Device& dev, const std::string& path, V4l2NodeInfo& out,
                     std::string& error) {
  out = {};
  out.path = path;
  const int fd = dev.open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    error = "camera " + path + ": open failed: " + std::strerror(errno);
    return false;
  }
  v4l2_capability cap{};
  if (dev.ioctl(fd, VIDIOC_QUERYCAP, &cap) != 0) {
    error = "camera " + path + ": VIDIOC_QUERYCAP failed: " + std::strerror(errno);
    dev.close(fd);
    return false;
  }
  const std::uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
  out.driver = cstr(cap.driver, sizeof cap.driver);
  out.card = cstr(cap.card, sizeof cap.card);
  out.bus_info = cstr(cap.bus_info, sizeof cap.bus_info);
  out.video_capture = (caps & V4L2_CAP_VIDEO_CAPTURE) != 0;
  out.meta_capture = (caps & V4L2_CAP_META_CAPTURE) != 0;
  const std::uint32_t type =
      out.video_capture ? V4L2_BUF_TYPE_VIDEO_CAPTURE : V4L2_BUF_TYPE_META_CAPTURE;
  for (std::uint32_t i = 0; i < 64 && (out.video_capture || out.meta_capture); ++i) {
    v4l2_fmtdesc fd_desc{};
    fd_desc.index = i;
    fd_desc.type = type;
    if (dev.ioctl(fd, VIDIOC_ENUM_FMT, &fd_desc) != 0) break;
    V4l2FormatInfo f;
    f.fourcc = fd_desc.pixelformat;
    f.description = cstr(fd_desc.description, sizeof fd_desc.description);
    for (std::uint32_t s = 0; out.video_capture && s < 256; ++s) {
      v4l2_frmsizeenum fs{};
      fs.index = s;
      fs.pixel_format = f.fourcc;
      if (dev.ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &fs) != 0) break;
      V4l2FrameSize size;
      if (fs.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        size.width = fs.discrete.width;
        size.height = fs.discrete.height;
      } else {
        size.width = fs.stepwise.max_width;
        size.height = fs.stepwise.max_height;
        size.stepwise = true;
      }
      size.rates_hz = rates(dev, fd, f.fourcc, size.width, size.height);
      f.sizes.push_back(std::move(size));
      if (fs.type != V4L2_FRMSIZE_TYPE_DISCRETE) break;
    }
    out.formats.push_back(std::move(f));
  }
  dev.close(fd);
  return true;
}

}  // namespace posed::drivers::camera
