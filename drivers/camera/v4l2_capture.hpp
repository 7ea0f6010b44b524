#pragma once
// V4L2 streaming capture of one video or metadata node: opens the node (by path, udev by-id link
// or serial number), negotiates format/size/rate (VIDIOC_S_FMT, VIDIOC_S_PARM), maps a ring of
// driver buffers (VIDIOC_REQBUFS/QUERYBUF + mmap), waits with poll() and a timeout, dequeues
// frames, detects drops from the driver's sequence numbers, reports the driver timestamp with
// its clock (V4L2_BUF_FLAG_TIMESTAMP_*), and reopens the node when the device disappears and
// comes back (USB replug). All kernel calls go through V4l2Device so a fake can drive it.
//
// Buffer ownership (as Aravis documents its own): a dequeued frame's bytes stay in the driver's
// mmap buffer until the next next() or release(), which re-queues it. The consumer converts
// them straight into a PayloadPool buffer: the conversion is the only copy.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/time.hpp"
#include "drivers/camera/pixel_formats.hpp"
#include "drivers/camera/v4l2_device.hpp"

namespace posed::drivers::camera {

enum class V4l2NodeKind : std::uint8_t {
  kVideo,     ///< V4L2_BUF_TYPE_VIDEO_CAPTURE (colour, depth, thermal)
  kMetadata,  ///< V4L2_BUF_TYPE_META_CAPTURE (UVC metadata node, V4L2_META_FMT_UVC / D4XX)
};

struct V4l2CaptureConfig {
  /// "/dev/video0", "/dev/v4l/by-id/usb-...-video-index0", or "serial:<serial>[:<index>]"
  /// (resolved through /dev/v4l/by-id; index defaults to 0)
  std::string device;
  V4l2NodeKind kind = V4l2NodeKind::kVideo;
  /// video nodes: the wire format to negotiate
  WireFormat format = WireFormat::kYuyv;
  /// metadata nodes: the fourcc (V4L2_META_FMT_UVC 'UVCH', or 'D4XX' on patched kernels)
  std::uint32_t meta_fourcc = fourcc('U', 'V', 'C', 'H');
  /// metadata nodes: further fourccs accepted when the driver offers one of them instead of
  /// meta_fourcc (the same uvc_meta_buf layout under another name: 'UVCH' vs 'D4XX')
  std::vector<std::uint32_t> meta_fourcc_alternatives;
  std::uint32_t width = 640;   ///< [px]
  std::uint32_t height = 480;  ///< [px]
  std::uint32_t fps = 30;      ///< requested frame rate [Hz]; 0 leaves the driver's choice
  /// driver buffers in the ring; the driver may grant fewer (at least 2 are needed)
  std::uint32_t buffer_count = 4;
  /// wait between reopen attempts while the device is gone [ms]
  int reopen_interval_ms = 500;
  /// directory of udev's by-id links, for "serial:" specs
  std::string by_id_dir = "/dev/v4l/by-id";
};

/// What the driver agreed to.
struct V4l2Negotiated {
  std::uint32_t fourcc = 0;
  std::uint32_t width = 0;         ///< [px]
  std::uint32_t height = 0;        ///< [px]
  std::uint32_t stride_bytes = 0;  ///< bytesperline [B]
  std::uint32_t frame_bytes = 0;   ///< sizeimage / meta buffersize [B]
  /// frame interval as the driver reports it [s] = num/den; 0/0 when S_PARM is unsupported
  std::uint32_t interval_num = 0, interval_den = 0;
  std::uint32_t buffer_count = 0;  ///< buffers granted by VIDIOC_REQBUFS
  std::string card;                ///< v4l2_capability.card
  std::string bus_info;            ///< v4l2_capability.bus_info
};

/// The clock of a V4L2 buffer timestamp (v4l2_buffer.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK).
enum class TimestampClock : std::uint8_t {
  kUnknown,    ///< V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN: not usable
  kMonotonic,  ///< V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC: CLOCK_MONOTONIC, i.e. the host clock
  kCopy,       ///< V4L2_BUF_FLAG_TIMESTAMP_COPY: copied from an output buffer (m2m), not a clock
};
std::string_view to_string(TimestampClock c);

/// One dequeued buffer. `bytes` is valid until the next next()/release()/close().
struct V4l2Frame {
  std::span<const std::byte> bytes;  ///< bytesused of the buffer
  std::uint32_t sequence = 0;        ///< driver frame sequence (v4l2_buffer.sequence)
  /// frames the driver skipped just before this one (gap in `sequence`)
  std::uint32_t dropped_before = 0;
  /// driver timestamp; on the host clock when clock == kMonotonic
  HostTime driver_stamp;
  TimestampClock clock = TimestampClock::kUnknown;
  /// V4L2_BUF_FLAG_TSTAMP_SRC_SOE: stamp taken at start of exposure (uvcvideo) rather than EOF
  bool stamp_at_start_of_exposure = false;
  /// V4L2_BUF_FLAG_ERROR: the driver delivered a damaged/partial frame (a status, not an error)
  bool partial = false;
  /// host CLOCK_MONOTONIC when the frame was dequeued
  HostTime host_receive;
  std::uint32_t buffer_index = 0;
};

enum class CaptureStatus : std::uint8_t {
  kFrame,       ///< `frame` is valid
  kTimeout,     ///< no frame within the timeout
  kDeviceLost,  ///< the device is gone (or not back yet); later calls try to reopen it
  kError,       ///< an unexpected failure; see last_error()
};
std::string_view to_string(CaptureStatus s);

struct V4l2CaptureCounters {
  std::uint64_t frames = 0;    ///< frames dequeued
  std::uint64_t dropped = 0;   ///< frames lost per sequence gaps
  std::uint64_t partial = 0;   ///< frames flagged V4L2_BUF_FLAG_ERROR
  std::uint64_t timeouts = 0;  ///< waits that ended without a frame
  std::uint64_t lost = 0;      ///< times the device disappeared
  std::uint64_t reopened = 0;  ///< successful reopens after a loss
  std::uint64_t errors = 0;    ///< other ioctl/poll failures
};

/// Resolves a device spec to a path: a plain path is returned as is; "serial:S[:I]" finds the
/// by-id link containing S and ending in "-video-index<I>". Empty with `error` set if none.
std::string resolve_v4l2_device(std::string_view spec, const std::string& by_id_dir,
                                std::string& error);

class V4l2Capture {
 public:
  V4l2Capture(V4l2Device& device, V4l2CaptureConfig config);
  ~V4l2Capture();
  V4l2Capture(const V4l2Capture&) = delete;
  V4l2Capture& operator=(const V4l2Capture&) = delete;

  /// Opens, negotiates, maps and starts streaming. false with a message naming the device,
  /// the ioctl and the errno text (or the format mismatch) on failure.
  bool open(std::string& error);
  /// Stops streaming, unmaps and closes. Idempotent.
  void close();
  bool is_open() const { return fd_ >= 0; }

  /// Re-queues the previous frame's buffer, then waits up to `timeout` for the next frame.
  /// After kDeviceLost, each call waits reopen_interval_ms (bounded by `timeout`) and tries to
  /// reopen; it never blocks much longer than `timeout`.
  CaptureStatus next(V4l2Frame& frame, Duration timeout);
  /// Hands the current frame's buffer back to the driver early (before the next next()).
  void release();

  const V4l2Negotiated& negotiated() const { return negotiated_; }
  const V4l2CaptureConfig& config() const { return config_; }
  const V4l2CaptureCounters& counters() const { return counters_; }
  const std::string& last_error() const { return last_error_; }
  /// the path actually opened (after by-id/serial resolution)
  const std::string& path() const { return path_; }
  /// the descriptor, for callers that poll several nodes together; -1 when closed
  int fd() const { return fd_; }

 private:
  struct Mapping {
    void* addr = nullptr;
    std::size_t length = 0;
  };
  bool negotiate(std::string& error);
  bool start_streaming(std::string& error);
  bool xioctl(unsigned long request, const char* name, void* arg, std::string& error);
  void lose_device(const char* what, int err);
  std::uint32_t buf_type() const;

  V4l2Device& dev_;
  V4l2CaptureConfig config_;
  std::string path_;
  int fd_ = -1;
  bool lost_ = false;
  bool streaming_ = false;
  std::vector<Mapping> buffers_;
  int held_index_ = -1;  // buffer dequeued and not yet re-queued
  bool have_sequence_ = false;
  std::uint32_t last_sequence_ = 0;
  V4l2Negotiated negotiated_;
  V4l2CaptureCounters counters_;
  std::string last_error_;
};

}  // namespace posed::drivers::camera
