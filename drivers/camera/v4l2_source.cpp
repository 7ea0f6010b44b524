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
  counts_.reopened.store(capture_.counters().reopened, std::memory_order_relaxed);
  switch (s) {
    case CaptureStatus::kFrame:
      chunk.bytes = frame_.bytes;
      chunk.host_receive = frame_.host_receive;
      chunk.channel = 0;
      counts_.count_chunk(frame_.bytes.size());
      return ReadStatus::kData;
    case CaptureStatus::kTimeout:
      return ReadStatus::kTimeout;
    case CaptureStatus::kDeviceLost:
      return ReadStatus::kDeviceLost;
    case CaptureStatus::kError:
      // Not open, or a failure the driver may recover from: the caller retries like a timeout;
      // the error text stays in capture().last_error().
      counts_.rejected.fetch_add(1, std::memory_order_relaxed);
      return ReadStatus::kTimeout;
  }
  return ReadStatus::kTimeout;
}

SourceCounters V4l2Source::counters() const { return counts_.snapshot(); }

}  // namespace posed::drivers::camera
