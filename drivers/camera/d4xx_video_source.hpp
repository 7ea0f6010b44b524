#pragma once
// A RealSense D4xx (D435i) colour or depth node together with its uvcvideo metadata node, as one
// Source. uvcvideo exposes each UVC streaming interface as two V4L2 nodes: the video node and a
// companion V4L2_BUF_TYPE_META_CAPTURE node whose buffers hold, per frame, struct uvc_meta_buf
// and the UVC payload header with Intel's metadata blocks (drivers/camera/d4xx_metadata.hpp).
// Both are streamed with their own mmap buffer ring and paired by v4l2_buffer.sequence, the
// rule librealsense's Linux backend applies (src/linux/backend-v4l2.cpp,
// buffers_mgr::verify_vd_md_sync: "Non-sequential Video and Metadata v4l buffers" when the
// sequences differ): uvcvideo completes a frame's video and metadata buffers together and gives
// both the same sequence.
//
// Delivery convention: a frame's metadata buffer comes out as channel 1 (wire format
// "uvc-meta-d4xx") immediately before the frame's bytes on channel 0, so a recording keeps both
// and a decoder downstream (D4xxMetadataLatch) has the metadata when the frame arrives. A frame
// whose metadata buffer is missing comes out alone on channel 0 (counted); a metadata buffer
// whose frame never came (the video node dropped it) is released unread (counted). Bytes stay
// in the drivers' mmap buffers until the next read(): no copies.

#include <atomic>
#include <cstdint>
#include <string>
#include <string_view>

#include "drivers/camera/v4l2_capture.hpp"
#include "drivers/common/source.hpp"

namespace posed::drivers::camera {

struct D4xxVideoConfig {
  /// the video node (colour YUYV/RGB8 or depth Z16), as for V4l2Source
  V4l2CaptureConfig video;
  /// stream the metadata node and pair its buffers with the frames
  bool metadata = true;
  /// the metadata node; empty = companion_metadata_node(video.device)
  std::string metadata_device;
  /// metadata buffers in their ring (small: ~100 B used of each)
  std::uint32_t metadata_buffer_count = 8;
  /// how long to wait for a frame's metadata buffer once the frame is there [ms]; uvcvideo
  /// completes both together, so this only covers scheduling between the two dequeues
  int metadata_wait_ms = 5;
};

/// The metadata node next to a video node: /dev/videoN -> /dev/video(N+1), a udev by-id link
/// "...-video-indexN" -> "...-video-index(N+1)", "serial:S[:N]" -> "serial:S:(N+1)" (uvcvideo
/// registers a streaming interface's metadata node right after its video node). Empty when
/// `video_device` has none of these forms.
std::string companion_metadata_node(std::string_view video_device);

struct D4xxVideoCounters {
  std::uint64_t frames = 0;                   ///< frames delivered on channel 0
  std::uint64_t frames_with_metadata = 0;     ///< of which preceded by their metadata buffer
  std::uint64_t frames_without_metadata = 0;  ///< of which without (metadata missing or node down)
  std::uint64_t metadata_orphaned = 0;        ///< metadata buffers whose frame never came
  std::uint64_t metadata_open_failures = 0;   ///< attempts to open the metadata node that failed
};

class D4xxVideoSource final : public Source {
 public:
  /// `device` serves both nodes (one fake in tests may stand for several nodes).
  D4xxVideoSource(std::string name, V4l2Device& device, D4xxVideoConfig config);
  std::string_view name() const override { return name_; }
  std::string_view wire_format(std::uint32_t channel) const override;
  /// Opens the video node (failure is an error) and the metadata node (failure is logged once
  /// with the reason and counted; frames then flow without metadata).
  bool open(std::string& error) override;
  ReadStatus read(RawChunk& chunk, Duration timeout) override;
  void request_stop() override { stop_.store(true, std::memory_order_relaxed); }
  SourceCounters counters() const override;

  /// the frame behind the last channel-0 chunk, or the frame about to follow a channel-1 chunk
  const V4l2Frame& last_frame() const { return frame_; }
  /// the metadata buffer behind the last channel-1 chunk
  const V4l2Frame& last_metadata() const { return metadata_frame_; }
  /// pairing counters (reader thread only)
  const D4xxVideoCounters& pairing_counters() const { return pairing_; }
  const V4l2Capture& video_capture() const { return video_; }
  const V4l2Capture& metadata_capture() const { return metadata_; }

 private:
  void open_metadata();
  /// Dequeues metadata buffers until the one for `sequence`; true when it is held in
  /// metadata_frame_.
  bool take_metadata_for(std::uint32_t sequence);
  ReadStatus deliver_frame(RawChunk& chunk);

  std::string name_;
  D4xxVideoConfig config_;
  V4l2Capture video_;
  V4l2Capture metadata_;
  V4l2Frame frame_;
  V4l2Frame metadata_frame_;
  bool holding_metadata_ = false;  // metadata_frame_ dequeued and not yet paired or dropped
  bool frame_pending_ = false;     // metadata went out; its frame goes out on the next read
  bool metadata_warned_ = false;
  std::uint64_t video_reopens_seen_ = 0;
  D4xxVideoCounters pairing_;
  std::atomic<bool> stop_{false};
  AtomicSourceCounters counts_;
};

}  // namespace posed::drivers::camera
