#include "drivers/camera/v4l2_capture.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"

namespace posed::drivers::camera {
namespace {

std::string cstr(const std::uint8_t* s, std::size_t n) {
  const auto* c = reinterpret_cast<const char*>(s);
  return std::string(c, strnlen(c, n));
}

/// errno values that mean the device itself went away (USB unplug, driver unbind), as opposed to
/// a request the driver refused.
bool is_gone(int err) { return err == ENODEV || err == ENXIO || err == EIO || err == ENOENT; }

}  // namespace

std::string_view to_string(TimestampClock c) {
  switch (c) {
    case TimestampClock::kUnknown:
      return "unknown";
    case TimestampClock::kMonotonic:
      return "monotonic";
    case TimestampClock::kCopy:
      return "copy";
  }
  return "unknown";
}

std::string_view to_string(CaptureStatus s) {
  switch (s) {
    case CaptureStatus::kFrame:
      return "frame";
    case CaptureStatus::kTimeout:
      return "timeout";
    case CaptureStatus::kDeviceLost:
      return "device_lost";
    case CaptureStatus::kError:
      return "error";
  }
  return "unknown";
}

std::string resolve_v4l2_device(std::string_view spec, const std::string& by_id_dir,
                                std::string& error) {
  constexpr std::string_view kSerial = "serial:";
  if (spec.substr(0, kSerial.size()) != kSerial) return std::string(spec);
  std::string serial(spec.substr(kSerial.size()));
  std::string index = "0";
  if (const auto colon = serial.find(':'); colon != std::string::npos) {
    index = serial.substr(colon + 1);
    serial.resize(colon);
  }
  // udev's 60-persistent-v4l.rules names links usb-<vendor>_<model>_<serial>-video-index<N>.
  const std::string suffix = "-video-index" + index;
  std::error_code ec;
  std::vector<std::string> hits;
  for (const auto& e : std::filesystem::directory_iterator(by_id_dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.find(serial) != std::string::npos && name.size() >= suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      hits.push_back(e.path().string());
    }
  }
  if (ec) {
    error = "camera " + std::string(spec) + ": cannot list " + by_id_dir + ": " + ec.message();
    return {};
  }
  if (hits.empty()) {
    error = "camera " + std::string(spec) + ": no " + by_id_dir + " entry with serial '" + serial +
            "' ending in " + suffix;
    return {};
  }
  std::sort(hits.begin(), hits.end());
  if (hits.size() > 1) {
    error = "camera " + std::string(spec) + ": serial matches " + std::to_string(hits.size()) +
            " devices (" + hits[0] + ", " + hits[1] + ")";
    return {};
  }
  return hits[0];
}

V4l2Capture::V4l2Capture(V4l2Device& device, V4l2CaptureConfig config)
    : dev_(device), config_(std::move(config)) {}

V4l2Capture::~V4l2Capture() { close(); }

std::uint32_t V4l2Capture::buf_type() const {
  return config_.kind == V4l2NodeKind::kVideo ? V4L2_BUF_TYPE_VIDEO_CAPTURE
                                              : V4L2_BUF_TYPE_META_CAPTURE;
}

bool V4l2Capture::xioctl(unsigned long request, const char* name, void* arg, std::string& error) {
  if (dev_.ioctl(fd_, request, arg) == 0) return true;
  const int err = errno;
  error = "camera " + path_ + ": " + name + " failed: " + std::strerror(err);
  errno = err;
  return false;
}

bool V4l2Capture::open(std::string& error) {
  if (fd_ >= 0) return true;
  path_ = resolve_v4l2_device(config_.device, config_.by_id_dir, error);
  if (path_.empty()) return false;
  // Non-blocking: DQBUF must never block; poll() does the waiting, with a timeout.
  fd_ = dev_.open(path_.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    error = "camera " + path_ + ": open failed: " + std::strerror(errno);
    return false;
  }
  if (!negotiate(error) || !start_streaming(error)) {
    const int err = errno;
    close();
    errno = err;
    return false;
  }
  have_sequence_ = false;
  return true;
}

bool V4l2Capture::negotiate(std::string& error) {
  v4l2_capability cap{};
  if (!xioctl(VIDIOC_QUERYCAP, "VIDIOC_QUERYCAP", &cap, error)) return false;
  const std::uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
  negotiated_ = {};
  negotiated_.card = cstr(cap.card, sizeof cap.card);
  negotiated_.bus_info = cstr(cap.bus_info, sizeof cap.bus_info);
  const std::uint32_t need =
      config_.kind == V4l2NodeKind::kVideo ? V4L2_CAP_VIDEO_CAPTURE : V4L2_CAP_META_CAPTURE;
  if ((caps & need) == 0 || (caps & V4L2_CAP_STREAMING) == 0) {
    error = "camera " + path_ + " (" + negotiated_.card + "): not a streaming " +
            (config_.kind == V4l2NodeKind::kVideo ? "video" : "metadata") + " capture node";
    return false;
  }

  v4l2_format fmt{};
  fmt.type = buf_type();
  if (config_.kind == V4l2NodeKind::kVideo) {
    fmt.fmt.pix.width = config_.width;
    fmt.fmt.pix.height = config_.height;
    fmt.fmt.pix.pixelformat = to_fourcc(config_.format);
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
  } else {
    fmt.fmt.meta.dataformat = config_.meta_fourcc;
  }
  if (!xioctl(VIDIOC_S_FMT, "VIDIOC_S_FMT", &fmt, error)) return false;
  if (config_.kind == V4l2NodeKind::kVideo) {
    // S_FMT adjusts what it cannot do rather than failing: check what we got.
    negotiated_.fourcc = fmt.fmt.pix.pixelformat;
    negotiated_.width = fmt.fmt.pix.width;
    negotiated_.height = fmt.fmt.pix.height;
    negotiated_.stride_bytes = fmt.fmt.pix.bytesperline;
    negotiated_.frame_bytes = fmt.fmt.pix.sizeimage;
    if (negotiated_.fourcc != to_fourcc(config_.format) || negotiated_.width != config_.width ||
        negotiated_.height != config_.height) {
      error = "camera " + path_ + ": asked for " + std::string(to_string(config_.format)) + " " +
              std::to_string(config_.width) + "x" + std::to_string(config_.height) +
              ", driver offers " + fourcc_to_string(negotiated_.fourcc) + " " +
              std::to_string(negotiated_.width) + "x" + std::to_string(negotiated_.height) +
              " (see posectl inspect camera)";
      return false;
    }
  } else {
    negotiated_.fourcc = fmt.fmt.meta.dataformat;
    negotiated_.frame_bytes = fmt.fmt.meta.buffersize;
    const auto& alt = config_.meta_fourcc_alternatives;
    if (negotiated_.fourcc != config_.meta_fourcc &&
        std::find(alt.begin(), alt.end(), negotiated_.fourcc) == alt.end()) {
      error = "camera " + path_ + ": metadata format " + fourcc_to_string(config_.meta_fourcc) +
              " not offered (driver has " + fourcc_to_string(negotiated_.fourcc) + ")";
      return false;
    }
  }

  if (config_.kind == V4l2NodeKind::kVideo && config_.fps > 0) {
    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    parm.parm.capture.timeperframe.numerator = 1;
    parm.parm.capture.timeperframe.denominator = config_.fps;
    std::string parm_error;
    if (xioctl(VIDIOC_S_PARM, "VIDIOC_S_PARM", &parm, parm_error)) {
      negotiated_.interval_num = parm.parm.capture.timeperframe.numerator;
      negotiated_.interval_den = parm.parm.capture.timeperframe.denominator;
      if (negotiated_.interval_num != 1 || negotiated_.interval_den != config_.fps) {
        POSED_LOG_WARN("camera %s: asked for %u Hz, driver set %u/%u s per frame", path_.c_str(),
                       config_.fps, negotiated_.interval_num, negotiated_.interval_den);
      }
    } else {
      // Some UVC devices have a fixed rate; streaming still works, the rate is the device's.
      POSED_LOG_WARN("%s (rate left to the device)", parm_error.c_str());
    }
  }
  return true;
}

bool V4l2Capture::start_streaming(std::string& error) {
  v4l2_requestbuffers req{};
  req.count = config_.buffer_count;
  req.type = buf_type();
  req.memory = V4L2_MEMORY_MMAP;
  if (!xioctl(VIDIOC_REQBUFS, "VIDIOC_REQBUFS", &req, error)) return false;
  if (req.count < 2) {
    error = "camera " + path_ + ": VIDIOC_REQBUFS granted " + std::to_string(req.count) +
            " buffers, need at least 2";
    return false;
  }
  negotiated_.buffer_count = req.count;
  buffers_.assign(req.count, Mapping{});
  for (std::uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer buf{};
    buf.type = buf_type();
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    if (!xioctl(VIDIOC_QUERYBUF, "VIDIOC_QUERYBUF", &buf, error)) return false;
    void* addr = dev_.mmap(buf.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_,
                           static_cast<off_t>(buf.m.offset));
    if (addr == MAP_FAILED) {
      error = "camera " + path_ + ": mmap of buffer " + std::to_string(i) +
              " failed: " + std::strerror(errno);
      return false;
    }
    buffers_[i] = {addr, buf.length};
  }
  for (std::uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer buf{};
    buf.type = buf_type();
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    if (!xioctl(VIDIOC_QBUF, "VIDIOC_QBUF", &buf, error)) return false;
  }
  int type = static_cast<int>(buf_type());
  if (!xioctl(VIDIOC_STREAMON, "VIDIOC_STREAMON", &type, error)) return false;
  streaming_ = true;
  return true;
}

void V4l2Capture::close() {
  if (fd_ < 0) return;
  if (streaming_) {
    int type = static_cast<int>(buf_type());
    dev_.ioctl(fd_, VIDIOC_STREAMOFF, &type);  // best effort: the device may be gone
    streaming_ = false;
  }
  for (auto& b : buffers_) {
    if (b.addr != nullptr) dev_.munmap(b.addr, b.length);
  }
  buffers_.clear();
  // Free the driver's buffers so a reopen can allocate them again (REQBUFS count 0).
  if (!lost_) {
    v4l2_requestbuffers req{};
    req.type = buf_type();
    req.memory = V4L2_MEMORY_MMAP;
    dev_.ioctl(fd_, VIDIOC_REQBUFS, &req);
  }
  dev_.close(fd_);
  fd_ = -1;
  held_index_ = -1;
}

void V4l2Capture::lose_device(const char* what, int err) {
  last_error_ =
      "camera " + path_ + ": " + what + ": " + std::strerror(err) + " (device gone; will reopen)";
  POSED_LOG_WARN("%s", last_error_.c_str());
  ++counters_.lost;
  lost_ = true;
  close();
}

void V4l2Capture::release() {
  if (fd_ < 0 || held_index_ < 0) return;
  v4l2_buffer buf{};
  buf.type = buf_type();
  buf.memory = V4L2_MEMORY_MMAP;
  buf.index = static_cast<std::uint32_t>(held_index_);
  held_index_ = -1;
  if (dev_.ioctl(fd_, VIDIOC_QBUF, &buf) != 0) {
    const int err = errno;
    if (is_gone(err)) {
      lose_device("VIDIOC_QBUF", err);
    } else {
      ++counters_.errors;
      last_error_ = "camera " + path_ + ": VIDIOC_QBUF failed: " + std::strerror(err);
    }
  }
}

CaptureStatus V4l2Capture::next(V4l2Frame& frame, Duration timeout) {
  const int timeout_ms = static_cast<int>(std::max<std::int64_t>(0, timeout.ns / 1'000'000));
  if (fd_ < 0) {
    if (!lost_) {
      last_error_ = "camera " + config_.device + ": not open";
      return CaptureStatus::kError;
    }
    // Gone: wait a little (bounded by the caller's timeout), then try once to reopen.
    dev_.poll(nullptr, 0, std::min(timeout_ms, config_.reopen_interval_ms));
    std::string error;
    if (!open(error)) {
      last_error_ = error;
      return CaptureStatus::kDeviceLost;
    }
    lost_ = false;
    ++counters_.reopened;
    POSED_LOG_NOTICE("camera %s: reopened", path_.c_str());
  }
  release();
  if (fd_ < 0) return CaptureStatus::kDeviceLost;

  pollfd pfd{fd_, POLLIN, 0};
  const int n = dev_.poll(&pfd, 1, timeout_ms);
  if (n < 0) {
    if (errno == EINTR) {
      ++counters_.timeouts;
      return CaptureStatus::kTimeout;
    }
    ++counters_.errors;
    last_error_ = "camera " + path_ + ": poll failed: " + std::strerror(errno);
    return CaptureStatus::kError;
  }
  if (n == 0) {
    ++counters_.timeouts;
    return CaptureStatus::kTimeout;
  }
  if ((pfd.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0 && (pfd.revents & POLLIN) == 0) {
    // uvcvideo signals a disconnect as POLLERR|POLLHUP (vb2 poll on a disconnected queue).
    lose_device("poll reports POLLERR/POLLHUP", ENODEV);
    return CaptureStatus::kDeviceLost;
  }

  v4l2_buffer buf{};
  buf.type = buf_type();
  buf.memory = V4L2_MEMORY_MMAP;
  if (dev_.ioctl(fd_, VIDIOC_DQBUF, &buf) != 0) {
    const int err = errno;
    if (err == EAGAIN) {
      ++counters_.timeouts;
      return CaptureStatus::kTimeout;
    }
    if (is_gone(err)) {
      lose_device("VIDIOC_DQBUF", err);
      return CaptureStatus::kDeviceLost;
    }
    ++counters_.errors;
    last_error_ = "camera " + path_ + ": VIDIOC_DQBUF failed: " + std::strerror(err);
    return CaptureStatus::kError;
  }
  frame = {};
  frame.host_receive = host_now();
  if (buf.index >= buffers_.size()) {
    ++counters_.errors;
    last_error_ = "camera " + path_ + ": VIDIOC_DQBUF returned buffer index " +
                  std::to_string(buf.index) + " of " + std::to_string(buffers_.size());
    return CaptureStatus::kError;
  }
  held_index_ = static_cast<int>(buf.index);
  const Mapping& m = buffers_[buf.index];
  const std::size_t used = std::min<std::size_t>(buf.bytesused, m.length);
  frame.bytes = {static_cast<const std::byte*>(m.addr), used};
  frame.buffer_index = buf.index;
  frame.sequence = buf.sequence;
  // The driver counts every frame it sees, queued buffer or not, so a sequence gap is a frame
  // lost for want of a free buffer (or on the bus).
  if (have_sequence_ && buf.sequence > last_sequence_ + 1) {
    frame.dropped_before = buf.sequence - last_sequence_ - 1;
    counters_.dropped += frame.dropped_before;
  }
  have_sequence_ = true;
  last_sequence_ = buf.sequence;
  switch (buf.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) {
    case V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC:
      frame.clock = TimestampClock::kMonotonic;
      break;
    case V4L2_BUF_FLAG_TIMESTAMP_COPY:
      frame.clock = TimestampClock::kCopy;
      break;
    default:
      frame.clock = TimestampClock::kUnknown;
  }
  frame.stamp_at_start_of_exposure =
      (buf.flags & V4L2_BUF_FLAG_TSTAMP_SRC_MASK) == V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
  frame.driver_stamp =
      HostTime::from_ns(static_cast<std::int64_t>(buf.timestamp.tv_sec) * 1'000'000'000 +
                        static_cast<std::int64_t>(buf.timestamp.tv_usec) * 1'000);
  frame.partial = (buf.flags & V4L2_BUF_FLAG_ERROR) != 0;
  if (frame.partial) ++counters_.partial;
  ++counters_.frames;
  return CaptureStatus::kFrame;
}

}  // namespace posed::drivers::camera
