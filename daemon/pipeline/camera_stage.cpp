#include "daemon/pipeline/camera_stage.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include "daemon/pipeline/thread_policy.hpp"
#include "drivers/common/log.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::pipeline {

namespace camera = drivers::camera;

const config::CameraSection& camera_section(const config::PosedConfig& config, CameraStream s) {
  switch (s) {
    case CameraStream::kVisible:
      return config.visible_camera;
    case CameraStream::kThermal:
      return config.thermal_camera;
    case CameraStream::kDepth:
      return config.depth_camera;
  }
  return config.visible_camera;
}

std::size_t CameraStage::pool_buffers(const config::PosedConfig& config) {
  // The queue, the frame being decoded, and what the fusion core's camera front end may hold:
  // frames waiting for a partner (3) and pairs waiting for the IMU (up to 6), and with the front
  // end on its own thread (frontend.own_thread) the frames posted to it between two window steps
  // (a scan period: 2 at 15-25 Hz, 4 to spare).
  return static_cast<std::size_t>(config.queues.image_capacity) + 16;
}

std::size_t CameraStage::frame_bytes(const config::CameraSection& section) {
  // Colour decodes to 3 bytes per pixel and raw thermal/depth to 2; a buffer sized for colour
  // holds any format the stream can switch to (a recording's channel decides, not the config).
  return static_cast<std::size_t>(section.width) * static_cast<std::size_t>(section.height) * 3;
}

CameraStage::CameraStage(const config::PosedConfig& config, CameraStream stream,
                         drivers::Source& source, SpscQueue<ImageItem>& queue, Wakeup& consumer,
                         Heartbeat& heartbeat, StreamCounters& counters)
    : config_(config),
      stream_(stream),
      section_(camera_section(config, stream)),
      source_(source),
      queue_(queue),
      consumer_(consumer),
      heartbeat_(heartbeat),
      counters_(counters),
      pool_(pool_buffers(config), frame_bytes(section_)),
      clock_(section_) {}

camera::FrameDecoder* CameraStage::decoder_for(std::string_view wire_format, std::uint32_t width,
                                               std::uint32_t height, std::uint32_t stride_bytes) {
  if (decoder_ && wire_format == decoder_format_ && width == decoder_width_ &&
      height == decoder_height_ && stride_bytes == decoder_stride_) {
    return decoder_.get();
  }
  const std::optional<camera::WireFormat> format = camera::wire_format_from_string(wire_format);
  if (!format) return nullptr;
  camera::FrameDecoderConfig c;
  c.format = *format;
  c.width = width;
  c.height = height;
  c.stride_bytes = stride_bytes;
  // A thermal camera's MJPEG is grey; the fusion core's thermal path wants one channel.
  c.mjpeg_to_mono8 = stream_ == CameraStream::kThermal;
  if (stream_ == CameraStream::kDepth) {
    c.depth_unit_m = static_cast<float>(config_.depth_camera.depth_unit_m);
  }
  decoder_ = std::make_unique<camera::FrameDecoder>(c);
  decoder_format_ = std::string(wire_format);
  decoder_width_ = width;
  decoder_height_ = height;
  decoder_stride_ = stride_bytes;
  return decoder_.get();
}

void CameraStage::handle_frame(const drivers::RawChunk& chunk, std::span<const std::byte> pixels,
                               camera::FrameDecoder& decoder, std::optional<HostTime> exposure) {
  Image image;
  camera::DecodeStatus status = decoder.decode(pixels, sequence_++, pool_, image);
  if (status == camera::DecodeStatus::kPoolEmpty && !source_.live()) {
    // A recording must lose nothing (replays are deterministic): wait for the fusion core to
    // return a buffer, as the queue would block, rather than drop the frame.
    const auto give_up = std::chrono::steady_clock::now() + kReplayBlockTimeout;
    while (status == camera::DecodeStatus::kPoolEmpty &&
           std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      heartbeat_.beat();
      status = decoder.decode(pixels, sequence_ - 1, pool_, image);
    }
  }
  // The frame is stamped even when it cannot be decoded: the clock must see every arrival.
  const HostTime stamp = exposure ? *exposure : clock_.stamp(chunk.host_receive);
  if (!exposure) log_clock_event(to_string(stream_), clock_.last_event());
  switch (status) {
    case camera::DecodeStatus::kOk:
    case camera::DecodeStatus::kPartial:
      break;
    case camera::DecodeStatus::kPoolEmpty:
      counters_.dropped.fetch_add(1, std::memory_order_relaxed);
      return;
    case camera::DecodeStatus::kPoolTooSmall:
    case camera::DecodeStatus::kBadFrame:
      counters_.malformed.fetch_add(1, std::memory_order_relaxed);
      return;
  }
  image.stamp = stamp;
  counters_.decoded.fetch_add(1, std::memory_order_relaxed);
  const PushResult r =
      queue_.push(ImageItem{std::move(image), false, chunk.host_receive, counters_.bad()});
  if (r != PushResult::kPushed) counters_.dropped.fetch_add(1, std::memory_order_relaxed);
  consumer_.signal();
}

void CameraStage::run() {
  const std::string thread = "posed-" + std::string(to_string(stream_));
  apply_thread_policy(thread, config_.threads.camera_source);
  drivers::RawChunk chunk;
  SourceReader reader(to_string(stream_), source_, heartbeat_, counters_);
  std::uint64_t frames = 0;
  while (reader.next(chunk)) {
    const std::string_view format = reader.wire_format(chunk);
    if (format == drivers::wire::kUvcMetaD4xx) {
      if (!clock_.on_metadata(chunk.bytes)) {
        counters_.malformed.fetch_add(1, std::memory_order_relaxed);
      }
      continue;
    }
    if (format.starts_with(drivers::wire::kRos1Prefix)) {
      handle_ros1_image(chunk, format);
    } else if (camera::FrameDecoder* decoder =
                   decoder_for(format, static_cast<std::uint32_t>(section_.width),
                               static_cast<std::uint32_t>(section_.height), 0)) {
      handle_frame(chunk, chunk.bytes, *decoder, std::nullopt);
    } else {
      reader.undecodable(chunk);
      continue;
    }
    // Often enough that a 15 Hz camera's newest arrival is never a second old in the status
    // (fill_stream_status() calls a stream silent for kStreamStaleAfter lost).
    if (++frames % 4 == 0) counters_.publish_clock(clock_.status());
  }
  counters_.publish_clock(clock_.status());
  queue_.push(ImageItem{{}, true, {}});
  consumer_.signal();
}

}  // namespace posed::pipeline
