#pragma once
// A scripted stand-in for a V4L2 capture node (uvcvideo-like), for tests on machines without
// /dev/video*. Buffers are real shared memory (memfd) mapped with the real mmap, so the capture
// code reads frames exactly as from a driver; ioctl answers follow linux/videodev2.h semantics
// (S_FMT adjusts to the nearest supported mode, REQBUFS may grant fewer buffers, DQBUF fails with
// EAGAIN when nothing is ready and ENODEV once the device is unplugged).

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <deque>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "drivers/camera/v4l2_device.hpp"

namespace posed::test {

struct FakeMode {
  std::uint32_t fourcc;
  std::uint32_t width;
  std::uint32_t height;
  std::uint32_t bytes_per_pixel;  ///< 0 for compressed (sizeimage = w*h)
};

struct FakeEvent {
  enum class Kind {
    kFrame,       ///< a frame becomes ready (needs a queued buffer)
    kTimeout,     ///< poll() times out once
    kDisconnect,  ///< the device is unplugged: POLLERR|POLLHUP, ENODEV from then on
  };
  Kind kind = Kind::kFrame;
  std::vector<std::byte> payload;
  std::uint32_t sequence = 0;
  std::uint32_t extra_flags = 0;  ///< e.g. V4L2_BUF_FLAG_ERROR
  std::int64_t stamp_us = 0;      ///< driver timestamp [us]
  std::uint32_t clock_flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
};

class FakeV4l2Device final : public drivers::camera::V4l2Device {
 public:
  // --- configuration (set by the test before use) ---
  std::set<std::string> present_paths{"/dev/video0"};
  std::uint32_t device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  std::vector<FakeMode> modes{{v4l2_fourcc('Y', 'U', 'Y', 'V'), 640, 480, 2}};
  /// metadata node: buffersize answered by S_FMT for any requested meta format in meta_formats
  std::set<std::uint32_t> meta_formats{};
  std::uint32_t meta_buffer_bytes = 4096;
  bool s_parm_supported = true;
  std::uint32_t max_fps = 30;              ///< S_PARM clamps the rate to this
  std::uint32_t max_buffers = 8;           ///< REQBUFS grants at most this many
  int failing_opens_after_disconnect = 0;  ///< open() attempts that fail (ENOENT) after unplug
  std::deque<FakeEvent> script;
  /// the descriptor open() returns; distinct per node when several share a FakeV4l2Bus
  int fd_number = 42;
  /// VIDIOC_ENUM_FRAMEINTERVALS answers (discrete, 1/fps) for every mode
  std::vector<std::uint32_t> frame_rates{30, 15};

  // --- observations ---
  std::vector<std::string> calls;  ///< ioctl names in order
  int opens = 0, closes = 0, waits = 0, open_fds = 0, mapped = 0;
  std::deque<std::uint32_t> queued;  ///< buffers owned by the "driver"
  bool streaming = false;

  ~FakeV4l2Device() override {
    if (memfd_ >= 0) ::close(memfd_);
  }

  int open(const char* path, int /*flags*/) override {
    ++opens;
    if (disconnected_) {
      if (failing_opens_after_disconnect > 0) {
        --failing_opens_after_disconnect;
        errno = ENOENT;
        return -1;
      }
      disconnected_ = false;  // plugged back in
    }
    if (present_paths.count(path) == 0) {
      errno = ENOENT;
      return -1;
    }
    ++open_fds;
    return fd_number;
  }
  int close(int fd) override {
    if (fd != fd_number) return set_errno(EBADF);
    ++closes;
    --open_fds;
    streaming = false;
    queued.clear();
    return 0;
  }

  void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset) override {
    if (fd != fd_number || memfd_ < 0) {
      errno = EINVAL;
      return MAP_FAILED;
    }
    void* p = ::mmap(nullptr, length, prot, flags, memfd_, offset);
    if (p != MAP_FAILED) ++mapped;
    return p;
  }
  int munmap(void* addr, std::size_t length) override {
    --mapped;
    return ::munmap(addr, length);
  }

  int poll(pollfd* fds, nfds_t nfds, int /*timeout_ms*/) override {
    if (nfds == 0) {
      ++waits;
      return 0;
    }
    fds[0].revents = 0;
    if (disconnected_) {
      fds[0].revents = POLLERR | POLLHUP;
      return 1;
    }
    if (script.empty()) return 0;
    switch (script.front().kind) {
      case FakeEvent::Kind::kTimeout:
        script.pop_front();
        return 0;
      case FakeEvent::Kind::kDisconnect:
        script.pop_front();
        disconnected_ = true;
        fds[0].revents = POLLERR | POLLHUP;
        return 1;
      case FakeEvent::Kind::kFrame:
        if (!streaming || queued.empty()) return 0;  // vb2: no buffer, nothing to wait for
        fds[0].revents = POLLIN;
        return 1;
    }
    return 0;
  }

  int ioctl(int fd, unsigned long request, void* arg) override {
    if (fd != fd_number) return set_errno(EBADF);
    if (disconnected_) {
      calls.push_back("ENODEV");
      return set_errno(ENODEV);
    }
    switch (request) {
      case VIDIOC_QUERYCAP: {
        calls.push_back("QUERYCAP");
        auto* cap = static_cast<v4l2_capability*>(arg);
        *cap = {};
        std::strcpy(reinterpret_cast<char*>(cap->driver), "uvcvideo");
        std::strcpy(reinterpret_cast<char*>(cap->card), "Fake Camera");
        std::strcpy(reinterpret_cast<char*>(cap->bus_info), "usb-fake-1");
        cap->capabilities = device_caps | V4L2_CAP_DEVICE_CAPS;
        cap->device_caps = device_caps;
        return 0;
      }
      case VIDIOC_S_FMT: {
        calls.push_back("S_FMT");
        auto* f = static_cast<v4l2_format*>(arg);
        if (f->type == V4L2_BUF_TYPE_META_CAPTURE) {
          if (meta_formats.empty()) return set_errno(EINVAL);
          if (meta_formats.count(f->fmt.meta.dataformat) == 0) {
            f->fmt.meta.dataformat = *meta_formats.begin();
          }
          f->fmt.meta.buffersize = meta_buffer_bytes;
          frame_bytes_ = meta_buffer_bytes;
          return 0;
        }
        if (f->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return set_errno(EINVAL);
        // Like uvcvideo: pick the requested format if offered, else the first; then the
        // nearest size of that format.
        const FakeMode* best = nullptr;
        for (const auto& m : modes) {
          if (m.fourcc != f->fmt.pix.pixelformat) continue;
          if (best == nullptr || distance(m, *f) < distance(*best, *f)) best = &m;
        }
        if (best == nullptr) best = &modes.front();
        f->fmt.pix.pixelformat = best->fourcc;
        f->fmt.pix.width = best->width;
        f->fmt.pix.height = best->height;
        f->fmt.pix.bytesperline = best->width * best->bytes_per_pixel;
        f->fmt.pix.sizeimage =
            best->width * best->height * (best->bytes_per_pixel ? best->bytes_per_pixel : 1);
        frame_bytes_ = f->fmt.pix.sizeimage;
        return 0;
      }
      case VIDIOC_S_PARM: {
        calls.push_back("S_PARM");
        if (!s_parm_supported) return set_errno(ENOTTY);
        auto* p = static_cast<v4l2_streamparm*>(arg);
        auto& t = p->parm.capture.timeperframe;
        if (t.numerator == 0 || t.denominator / t.numerator > max_fps) {
          t.numerator = 1;
          t.denominator = max_fps;
        }
        return 0;
      }
      case VIDIOC_REQBUFS: {
        calls.push_back("REQBUFS");
        auto* r = static_cast<v4l2_requestbuffers*>(arg);
        if (r->memory != V4L2_MEMORY_MMAP) return set_errno(EINVAL);
        if (r->count == 0) return 0;
        r->count = std::min(r->count, max_buffers);
        buffer_count_ = r->count;
        stride_ = (frame_bytes_ + 4095) / 4096 * 4096;
        if (memfd_ >= 0) ::close(memfd_);
        memfd_ = ::memfd_create("fake-v4l2", MFD_CLOEXEC);
        if (memfd_ < 0 || ::ftruncate(memfd_, static_cast<off_t>(stride_ * buffer_count_)) != 0) {
          return set_errno(ENOMEM);
        }
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        calls.push_back("QUERYBUF");
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffer_count_) return set_errno(EINVAL);
        b->length = frame_bytes_;
        b->m.offset = static_cast<std::uint32_t>(b->index * stride_);
        return 0;
      }
      case VIDIOC_QBUF: {
        calls.push_back("QBUF");
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffer_count_) return set_errno(EINVAL);
        for (auto q : queued) {
          if (q == b->index) return set_errno(EINVAL);  // already queued
        }
        queued.push_back(b->index);
        return 0;
      }
      case VIDIOC_DQBUF: {
        calls.push_back("DQBUF");
        if (!streaming || queued.empty() || script.empty() ||
            script.front().kind != FakeEvent::Kind::kFrame) {
          return set_errno(EAGAIN);
        }
        FakeEvent e = std::move(script.front());
        script.pop_front();
        auto* b = static_cast<v4l2_buffer*>(arg);
        const std::uint32_t index = queued.front();
        queued.pop_front();
        const std::size_t n = std::min<std::size_t>(e.payload.size(), frame_bytes_);
        if (::pwrite(memfd_, e.payload.data(), n, static_cast<off_t>(index * stride_)) !=
            static_cast<ssize_t>(n)) {
          return set_errno(EIO);
        }
        b->index = index;
        b->bytesused = static_cast<std::uint32_t>(n);
        b->sequence = e.sequence;
        b->flags = e.clock_flags | e.extra_flags;
        b->timestamp.tv_sec = e.stamp_us / 1'000'000;
        b->timestamp.tv_usec = e.stamp_us % 1'000'000;
        return 0;
      }
      case VIDIOC_ENUM_FMT: {
        calls.push_back("ENUM_FMT");
        auto* f = static_cast<v4l2_fmtdesc*>(arg);
        std::vector<std::uint32_t> fourccs;
        if (f->type == V4L2_BUF_TYPE_META_CAPTURE) {
          fourccs.assign(meta_formats.begin(), meta_formats.end());
        } else {
          for (const auto& m : modes) {
            if (std::find(fourccs.begin(), fourccs.end(), m.fourcc) == fourccs.end()) {
              fourccs.push_back(m.fourcc);
            }
          }
        }
        if (f->index >= fourccs.size()) return set_errno(EINVAL);
        f->pixelformat = fourccs[f->index];
        std::snprintf(reinterpret_cast<char*>(f->description), sizeof f->description, "fake %u",
                      f->index);
        return 0;
      }
      case VIDIOC_ENUM_FRAMESIZES: {
        calls.push_back("ENUM_FRAMESIZES");
        auto* f = static_cast<v4l2_frmsizeenum*>(arg);
        std::uint32_t k = 0;
        for (const auto& m : modes) {
          if (m.fourcc != f->pixel_format) continue;
          if (k++ == f->index) {
            f->type = V4L2_FRMSIZE_TYPE_DISCRETE;
            f->discrete.width = m.width;
            f->discrete.height = m.height;
            return 0;
          }
        }
        return set_errno(EINVAL);
      }
      case VIDIOC_ENUM_FRAMEINTERVALS: {
        calls.push_back("ENUM_FRAMEINTERVALS");
        auto* f = static_cast<v4l2_frmivalenum*>(arg);
        bool known = false;
        for (const auto& m : modes) {
          known |= m.fourcc == f->pixel_format && m.width == f->width && m.height == f->height;
        }
        if (!known || f->index >= frame_rates.size()) return set_errno(EINVAL);
        f->type = V4L2_FRMIVAL_TYPE_DISCRETE;
        f->discrete.numerator = 1;
        f->discrete.denominator = frame_rates[f->index];
        return 0;
      }
      case VIDIOC_STREAMON:
        calls.push_back("STREAMON");
        streaming = true;
        return 0;
      case VIDIOC_STREAMOFF:
        calls.push_back("STREAMOFF");
        streaming = false;
        queued.clear();
        return 0;
      default:
        calls.push_back("other");
        return set_errno(ENOTTY);
    }
  }

  /// Appends a frame event whose payload is `bytes` bytes of value `fill`.
  void add_frame(std::uint32_t sequence, std::size_t bytes, std::uint8_t fill,
                 std::int64_t stamp_us = 0, std::uint32_t extra_flags = 0) {
    FakeEvent e;
    e.payload.assign(bytes, static_cast<std::byte>(fill));
    e.sequence = sequence;
    e.stamp_us = stamp_us;
    e.extra_flags = extra_flags;
    script.push_back(std::move(e));
  }
  void add(FakeEvent::Kind kind) {
    FakeEvent e;
    e.kind = kind;
    script.push_back(std::move(e));
  }
  int count(const std::string& call) const {
    int n = 0;
    for (const auto& c : calls) n += c == call ? 1 : 0;
    return n;
  }
  bool disconnected() const { return disconnected_; }

 private:
  static int set_errno(int e) {
    errno = e;
    return -1;
  }
  static std::int64_t distance(const FakeMode& m, const v4l2_format& f) {
    return std::abs(static_cast<std::int64_t>(m.width) - f.fmt.pix.width) +
           std::abs(static_cast<std::int64_t>(m.height) - f.fmt.pix.height);
  }
  bool disconnected_ = false;
  int memfd_ = -1;
  std::uint32_t buffer_count_ = 0;
  std::uint32_t frame_bytes_ = 0;
  std::size_t stride_ = 0;
};

/// Several fake nodes behind one V4l2Device, routed by path (open) and descriptor (the rest),
/// like the video and metadata nodes of one UVC camera: each attached node gets its own fd.
class FakeV4l2Bus final : public drivers::camera::V4l2Device {
 public:
  int waits = 0;  ///< poll() calls without descriptors (reopen back-off)

  void attach(const std::string& path, FakeV4l2Device& node) {
    node.present_paths = {path};
    node.fd_number = next_fd_++;
    by_path_[path] = &node;
    by_fd_[node.fd_number] = &node;
  }
  int open(const char* path, int flags) override {
    const auto it = by_path_.find(path);
    if (it == by_path_.end()) {
      errno = ENOENT;
      return -1;
    }
    return it->second->open(path, flags);
  }
  int close(int fd) override { return node(fd) ? node(fd)->close(fd) : bad(); }
  int ioctl(int fd, unsigned long request, void* arg) override {
    return node(fd) ? node(fd)->ioctl(fd, request, arg) : bad();
  }
  void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset) override {
    if (node(fd) == nullptr) {
      errno = EBADF;
      return MAP_FAILED;
    }
    void* p = node(fd)->mmap(length, prot, flags, fd, offset);
    if (p != MAP_FAILED) mapped_by_[p] = node(fd);
    return p;
  }
  int munmap(void* addr, std::size_t length) override {
    const auto it = mapped_by_.find(addr);
    if (it == mapped_by_.end()) return ::munmap(addr, length);
    FakeV4l2Device* n = it->second;
    mapped_by_.erase(it);
    return n->munmap(addr, length);
  }
  int poll(pollfd* fds, nfds_t nfds, int timeout_ms) override {
    if (nfds == 0) {
      ++waits;
      return 0;
    }
    return node(fds[0].fd) ? node(fds[0].fd)->poll(fds, nfds, timeout_ms) : bad();
  }

 private:
  FakeV4l2Device* node(int fd) {
    const auto it = by_fd_.find(fd);
    return it == by_fd_.end() ? nullptr : it->second;
  }
  static int bad() {
    errno = EBADF;
    return -1;
  }
  int next_fd_ = 100;
  std::map<std::string, FakeV4l2Device*> by_path_;
  std::map<int, FakeV4l2Device*> by_fd_;
  std::map<void*, FakeV4l2Device*> mapped_by_;
};

}  // namespace posed::test
