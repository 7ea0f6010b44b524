#pragma once
// A camera behind V4L2 as a Source (drivers/common/source.hpp): each read() returns one frame's
// bytes exactly as the driver delivered them (channel 0), pointing into the driver's mmap buffer
// until the next read(), so the recorder taps them and a FrameDecoder converts them into a pool
// buffer without an intermediate copy. The frame's V4L2 details (sequence, drops, driver stamp
// and its clock, partial flag) are available from last_frame() after each kData.

#include <atomic>
#include <string>

#include "drivers/camera/v4l2_capture.hpp"
#include "drivers/common/source.hpp"

namespace posed::drivers::camera {

class V4l2Source final : public Source {
 public:
  V4l2Source(std::string name, V4l2Device& device, V4l2CaptureConfig config);
  std::string_view name() const override { return name_; }
  std::string_view wire_format(std::uint32_t channel) const override {
    return channel == 0 ? to_string(capture_.config().format) : std::string_view{};
  }
  bool open(std::string& error) override;
  /// Waits at most `timeout`; request_stop() takes effect at the next read or within one
  /// timeout of a blocked one.
  ReadStatus read(RawChunk& chunk, Duration timeout) override;
  void request_stop() override { stop_.store(true, std::memory_order_relaxed); }
  SourceCounters counters() const override;
  /// the frame behind the last kData
  const V4l2Frame& last_frame() const { return frame_; }
  const V4l2Capture& capture() const { return capture_; }

 private:
  std::string name_;
  V4l2Capture capture_;
  V4l2Frame frame_;
  std::atomic<bool> stop_{false};
  AtomicSourceCounters counts_;
};

}  // namespace posed::drivers::camera
