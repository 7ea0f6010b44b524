// The camera stage's decoder for images imported from a ROS 1 bag (docs/import.md):
// sensor_msgs/Image in any encoding drivers/camera decodes (rgb8, bgr8, mono8, mono16, 16UC1,
// yuv422), at the size and row step the message says, and sensor_msgs/CompressedImage (JPEG,
// at the configured size).
//
// Time: a camera with a clock (visible, the D435i) was stamped by its ROS driver from the
// device's hardware clock, so header.stamp already is the exposure time on the bag's clock and
// is used as it is. A camera without one (thermal, the PLUG 617: M2DGR's driver stamped frames
// on arrival) goes through the camera clock like a live frame, with header.stamp as its arrival.

#include "daemon/pipeline/camera_stage.hpp"
#include "drivers/common/log.hpp"
#include "drivers/common/wire_format.hpp"
#include "drivers/recording/ros1_messages.hpp"

namespace posed::pipeline {

namespace ros1 = drivers::recording::ros1;
namespace camera = drivers::camera;

void CameraStage::handle_ros1_image(const drivers::RawChunk& chunk, std::string_view format) {
  const auto malformed = [&](std::string_view what) {
    if (counters_.malformed.fetch_add(1, std::memory_order_relaxed) == 0) {
      POSED_LOG_WARN("%s: %.*s (%zu B): skipped (said once)", to_string(stream_).data(),
                     static_cast<int>(what.size()), what.data(), chunk.bytes.size());
    }
  };
  std::int64_t stamp_ns = 0;
  std::span<const std::byte> pixels;
  camera::FrameDecoder* decoder = nullptr;
  if (format == drivers::wire::kRos1Image) {
    ros1::Image msg;
    if (ros1::decode_image(chunk.bytes, msg) != ros1::Ros1Status::kOk) {
      malformed("malformed sensor_msgs/Image");
      return;
    }
    const std::optional<camera::WireFormat> wire = ros1::camera_wire_format(msg);
    if (!wire) {
      malformed("sensor_msgs/Image encoding posed does not decode");
      return;
    }
    decoder = decoder_for(camera::to_string(*wire), msg.width, msg.height, msg.step);
    stamp_ns = msg.header.stamp_ns;
    pixels = msg.data;
  } else if (format == drivers::wire::kRos1CompressedImage) {
    ros1::CompressedImage msg;
    if (ros1::decode_compressed_image(chunk.bytes, msg) != ros1::Ros1Status::kOk) {
      malformed("malformed sensor_msgs/CompressedImage");
      return;
    }
    if (msg.format.find("jpeg") == std::string_view::npos) {
      malformed("sensor_msgs/CompressedImage not JPEG");
      return;
    }
    decoder = decoder_for(camera::to_string(camera::WireFormat::kMjpeg),
                          static_cast<std::uint32_t>(section_.width),
                          static_cast<std::uint32_t>(section_.height), 0);
    stamp_ns = msg.header.stamp_ns;
    pixels = msg.data;
  } else {
    malformed("a ROS 1 message type with no camera decoder");
    return;
  }
  if (decoder == nullptr) {
    malformed("no decoder for the image's format");
    return;
  }
  if (section_.clock_kind != "none") {
    handle_frame(chunk, pixels, *decoder, HostTime::from_ns(stamp_ns));
  } else {
    drivers::RawChunk arrival = chunk;
    arrival.host_receive = HostTime::from_ns(stamp_ns);
    handle_frame(arrival, pixels, *decoder, std::nullopt);
  }
}

}  // namespace posed::pipeline
