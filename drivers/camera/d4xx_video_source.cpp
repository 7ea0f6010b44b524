#include "drivers/camera/d4xx_video_source.hpp"

#include <charconv>

#include "drivers/common/log.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::drivers::camera {
namespace {

/// Splits `s` into the text before a trailing decimal number and that number; false if `s`
/// does not end in digits.
bool split_trailing_number(std::string_view s, std::string_view& head, unsigned& number) {
  std::size_t i = s.size();
  while (i > 0 && s[i - 1] >= '0' && s[i - 1] <= '9') --i;
  if (i == s.size()) return false;
  const auto r = std::from_chars(s.data() + i, s.data() + s.size(), number);
  if (r.ec != std::errc{}) return false;
  head = s.substr(0, i);
  return true;
}

V4l2CaptureConfig metadata_config(const D4xxVideoConfig& c) {
  V4l2CaptureConfig m;
  m.device =
      c.metadata_device.empty() ? companion_metadata_node(c.video.device) : c.metadata_device;
  m.kind = V4l2NodeKind::kMetadata;
  // Kernels with Intel's D4xx support name the format 'D4XX' (linux/videodev2.h
  // V4L2_META_FMT_D4XX, librealsense src/linux/backend-v4l2.h); plain uvcvideo calls the same
  // uvc_meta_buf layout 'UVCH' (V4L2_META_FMT_UVC).
  m.meta_fourcc = fourcc('D', '4', 'X', 'X');
  m.meta_fourcc_alternatives = {fourcc('U', 'V', 'C', 'H')};
  m.buffer_count = c.metadata_buffer_count;
  m.reopen_interval_ms = c.video.reopen_interval_ms;
  m.by_id_dir = c.video.by_id_dir;
  return m;
}

}  // namespace

std::string companion_metadata_node(std::string_view video) {
  std::string_view head;
  unsigned n = 0;
  constexpr std::string_view kSerial = "serial:";
  if (video.substr(0, kSerial.size()) == kSerial) {
    const std::string_view rest = video.substr(kSerial.size());
    const auto colon = rest.find(':');
    if (colon == std::string_view::npos) return std::string(video) + ":1";
    if (!split_trailing_number(rest.substr(colon + 1), head, n) || !head.empty()) return {};
    return std::string(video.substr(0, kSerial.size() + colon + 1)) + std::to_string(n + 1);
  }
  if (!split_trailing_number(video, head, n)) return {};
  const bool dev_video = head.size() >= 5 && head.substr(head.size() - 5) == "video";
  const bool by_id = head.size() >= 12 && head.substr(head.size() - 12) == "-video-index";
  if (!dev_video && !by_id) return {};
  return std::string(head) + std::to_string(n + 1);
}

D4xxVideoSource::D4xxVideoSource(std::string name, V4l2Device& device, D4xxVideoConfig config)
    : name_(std::move(name)),
      config_(std::move(config)),
      video_(device, config_.video),
      metadata_(device, metadata_config(config_)) {}

std::string_view D4xxVideoSource::wire_format(std::uint32_t channel) const {
  if (channel == 0) return to_string(config_.video.format);
  if (channel == 1 && config_.metadata) return wire::kUvcMetaD4xx;
  return {};
}

void D4xxVideoSource::open_metadata() {
  if (!config_.metadata || metadata_.is_open()) return;
  holding_metadata_ = false;
  std::string error;
  if (metadata_.config().device.empty()) {
    error = "no metadata node known for " + config_.video.device + " (set metadata_device)";
  } else if (metadata_.open(error)) {
    return;
  }
  ++pairing_.metadata_open_failures;
  if (!metadata_warned_) {
    // Once: a kernel without uvcvideo metadata support fails here on every reopen.
    POSED_LOG_WARN("%s: frame metadata unavailable, frames carry no hardware timestamp: %s",
                   name_.c_str(), error.c_str());
    metadata_warned_ = true;
  }
}

bool D4xxVideoSource::open(std::string& error) {
  if (!video_.open(error)) return false;
  video_reopens_seen_ = video_.counters().reopened;
  open_metadata();
  return true;
}

bool D4xxVideoSource::take_metadata_for(std::uint32_t sequence) {
  if (!metadata_.is_open() && metadata_.counters().lost == 0) return false;
  for (;;) {
    if (!holding_metadata_) {
      if (metadata_.next(metadata_frame_, Duration::from_ms(config_.metadata_wait_ms)) !=
          CaptureStatus::kFrame) {
        return false;
      }
      holding_metadata_ = true;
    }
    // Signed distance: sequences are u32 and may wrap.
    const auto ahead = static_cast<std::int32_t>(metadata_frame_.sequence - sequence);
    if (ahead == 0) {
      holding_metadata_ = false;  // handed out; the next next() re-queues its buffer
      return true;
    }
    if (ahead > 0) return false;   // this frame's metadata was lost; keep the buffer for later
    ++pairing_.metadata_orphaned;  // its frame was dropped by the video node
    holding_metadata_ = false;
  }
}

ReadStatus D4xxVideoSource::deliver_frame(RawChunk& chunk) {
  chunk.bytes = frame_.bytes;
  chunk.host_receive = frame_.host_receive;
  chunk.channel = 0;
  ++pairing_.frames;
  counts_.count_chunk(frame_.bytes.size());
  return ReadStatus::kData;
}

ReadStatus D4xxVideoSource::read(RawChunk& chunk, Duration timeout) {
  if (stop_.load(std::memory_order_relaxed)) {
    video_.close();
    metadata_.close();
    return ReadStatus::kEndOfStream;
  }
  if (frame_pending_) {
    frame_pending_ = false;
    return deliver_frame(chunk);
  }
  const CaptureStatus s = video_.next(frame_, timeout);
  counts_.reopened.store(video_.counters().reopened, std::memory_order_relaxed);
  switch (s) {
    case CaptureStatus::kFrame:
      break;
    case CaptureStatus::kTimeout:
      return ReadStatus::kTimeout;
    case CaptureStatus::kDeviceLost:
      // The metadata node goes with the video node; its sequence restarts with the video's.
      metadata_.close();
      holding_metadata_ = false;
      return ReadStatus::kDeviceLost;
    case CaptureStatus::kError:
      counts_.rejected.fetch_add(1, std::memory_order_relaxed);
      return ReadStatus::kTimeout;
  }
  if (video_.counters().reopened != video_reopens_seen_) {
    video_reopens_seen_ = video_.counters().reopened;
    metadata_.close();
    open_metadata();
  }
  if (config_.metadata && take_metadata_for(frame_.sequence)) {
    ++pairing_.frames_with_metadata;
    frame_pending_ = true;
    chunk.bytes = metadata_frame_.bytes;
    chunk.host_receive = metadata_frame_.host_receive;
    chunk.channel = 1;
    counts_.count_chunk(metadata_frame_.bytes.size());
    return ReadStatus::kData;
  }
  ++pairing_.frames_without_metadata;
  return deliver_frame(chunk);
}

SourceCounters D4xxVideoSource::counters() const { return counts_.snapshot(); }

}  // namespace posed::drivers::camera
