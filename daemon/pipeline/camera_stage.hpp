#pragma once
// A camera stage (one thread per camera): Source -> FrameDecoder (wire pixels into a pool
// buffer, no intermediate copy) -> CameraClock (D4xx metadata hardware clock, or regularised
// arrival) -> the camera's image queue to the fusion stage. Source channel 0 carries frames in
// the Source's pixel format, channel 1 the D4xx metadata that precedes each frame.

#include <memory>

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
  /// The decoder for a pixel format; null (counted as undecodable) for one posed cannot decode.
  drivers::camera::FrameDecoder* decoder_for(std::string_view wire_format);
  void handle_frame(const drivers::RawChunk& chunk, drivers::camera::FrameDecoder& decoder);

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
  std::unique_ptr<drivers::camera::FrameDecoder> decoder_;
  std::uint64_t sequence_ = 0;
};

}  // namespace posed::pipeline
