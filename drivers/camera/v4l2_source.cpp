#include "drivers/camera/v4l2_source.hpp"

namespace posed::drivers::camera {

V4l2Source::V4l2Source(std::string name, V4l2Device& device, V4l2CaptureConfig config)
    : name_(std::move(name)), capture_(device, std::move(config)) {}

bool V4l2Source::open(std::string& error) { return capture_.open(error); }

ReadStatus V4l2Source::read(RawChunk& chunk, Duration timeout) {
  if (stop_.load(std::memory_order_relaxed)) {
    capture_.close();
    return ReadStatus::kEndOfStream;
  }
  const CaptureStatus s = capture_.next(frame_, timeout);
  reopened_.store(capture_.counters().reopened, std::memory_order_relaxed);
  switch (s) {
    case CaptureStatus::kFrame:
      chunk.bytes = frame_.bytes;
      chunk.host_receive = frame_.host_receive;
      chunk.channel = 0;
      chunks_.fetch_add(1, std::memory_order_relaxed);
      bytes_.fetch_add(frame_.bytes.size(), std::memory_order_relaxed);
      return ReadStatus::kData;
    case CaptureStatus::kTimeout:
      return ReadStatus::kTimeout;
    case CaptureStatus::kDeviceLost:
      return ReadStatus::kDeviceLost;
    case CaptureStatus::kError:
      // Not open, or a failure the driver may recover from: the caller retries like a timeout;
      // the error text stays in capture().last_error().
      rejected_.fetch_add(1, std::memory_order_relaxed);
      return ReadStatus::kTimeout;
  }
  return ReadStatus::kTimeout;
}

SourceCounters V4l2Source::counters() const {
  SourceCounters c;
  c.chunks = chunks_.load(std::memory_order_relaxed);
  c.bytes = bytes_.load(std::memory_order_relaxed);
  c.rejected = rejected_.load(std::memory_order_relaxed);
  c.reopened = reopened_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace posed::drivers::camera
