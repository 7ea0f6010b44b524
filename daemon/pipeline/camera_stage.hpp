#pragma once
// A camera stage (one thread per camera): Source -> FrameDecoder (wire pixels into a pool
// buffer, no intermediate copy) -> CameraClock (D4xx metadata hardware clock, or regularised
// arrival) -> the camera's image queue to the fusion stage. Source channel 0 carries frames in
// the Source's pixel format, channel 1 the D4xx metadata that precedes each frame.

#include <memory>
#include <optional>
#include <span>

#include "core/payload_pool.hpp"
#include "core/spsc_queue.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/camera_clock.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "daemon/pipeline/wakeup.hpp"
#include "drivers/camera/frame_decoder.hpp"
#include "drivers/common/source.hpp"

namespace posed::pipeline {

/// The config section of a camera stream.
const config::CameraSection& camera_section(const config::PosedConfig& config, CameraStream s);

class CameraStage {
 public:
  CameraStage(const config::PosedConfig& config, CameraStream stream, drivers::Source& source,
              SpscQueue<ImageItem>& queue, Wakeup& consumer, Heartbeat& heartbeat,
              StreamCounters& counters);
  /// Runs until the Source ends, then forwards end-of-stream.
  void run();

  /// Pool buffers: the frames queued, the one being decoded, and a few the fusion core holds
  /// (a visible frame waiting for its thermal partner, the tracker's previous frame).
  static std::size_t pool_buffers(const config::PosedConfig& config);
  /// Bytes of one decoded frame of the largest format the stream can produce [B].
  static std::size_t frame_bytes(const config::CameraSection& section);

 private:
  /// The decoder for a pixel format at a size; null (counted as undecodable) for one posed
  /// cannot decode. Made again only when format or geometry change.
  drivers::camera::FrameDecoder* decoder_for(std::string_view wire_format, std::uint32_t width,
                                             std::uint32_t height, std::uint32_t stride_bytes);
  /// Decodes and queues one frame. `exposure`: the frame's stamp when its source already put it
  /// on the host clock; otherwise the camera clock stamps it from `chunk.host_receive`.
  void handle_frame(const drivers::RawChunk& chunk, std::span<const std::byte> pixels,
                    drivers::camera::FrameDecoder& decoder, std::optional<HostTime> exposure);
  /// sensor_msgs/Image and CompressedImage from an imported ROS 1 bag (camera_stage_ros1.cpp).
  void handle_ros1_image(const drivers::RawChunk& chunk, std::string_view wire_format);

  const config::PosedConfig& config_;
  CameraStream stream_;
  const config::CameraSection& section_;
  drivers::Source& source_;
  SpscQueue<ImageItem>& queue_;
  Wakeup& consumer_;
  Heartbeat& heartbeat_;
  StreamCounters& counters_;

  PayloadPool pool_;
  CameraClock clock_;
  std::string decoder_format_;
  std::uint32_t decoder_width_ = 0, decoder_height_ = 0, decoder_stride_ = 0;
  std::unique_ptr<drivers::camera::FrameDecoder> decoder_;
  std::uint64_t sequence_ = 0;
};

}  // namespace posed::pipeline
