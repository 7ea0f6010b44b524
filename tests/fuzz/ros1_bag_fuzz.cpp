// libFuzzer target: the ROS 1 bag reader (records, index, chunk decompression) and the ROS 1
// message decoders must accept any bytes, never read outside them, always terminate, and hand
// out messages only on connections they know.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "drivers/recording/ros1_bag_reader.hpp"
#include "drivers/recording/ros1_messages.hpp"

namespace ros1 = posed::drivers::recording::ros1;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto bytes = std::span(reinterpret_cast<const std::byte*>(data), size);
  for (const bool use_index : {true, false}) {
    ros1::BagReaderOptions options;
    options.use_index = use_index;
    // Chunk sizes come from the input: keep what one may claim small for the fuzzer's memory.
    options.max_chunk_bytes = 1u << 20;
    ros1::BagReader reader;
    std::string error;
    if (!reader.open_bytes(bytes, error, options)) return 0;
    ros1::BagMessage m;
    for (int n = 0; n < 100000 && reader.next(m); ++n) {
      if (m.connection == nullptr || reader.connections().count(m.connection->id) == 0) {
        std::abort();
      }
      // Every decoder on every message: none may read past it, whatever its type says.
      ros1::Header h;
      ros1::PointCloud2 cloud;
      ros1::Image image;
      ros1::CompressedImage compressed;
      ros1::Imu imu;
      ros1::CameraInfo info;
      ros1::decode_header(m.data, h);
      if (ros1::decode_point_cloud2(m.data, cloud) == ros1::Ros1Status::kOk) {
        for (std::size_t i = 0; i < cloud.point_count() && i < 64; ++i) {
          if (cloud.point(i).size() != cloud.point_step) std::abort();
        }
      }
      if (ros1::decode_image(m.data, image) == ros1::Ros1Status::kOk) {
        ros1::camera_wire_format(image);
      }
      ros1::decode_compressed_image(m.data, compressed);
      ros1::decode_imu(m.data, imu);
      if (ros1::decode_camera_info(m.data, info) == ros1::Ros1Status::kOk && info.d_count > 0) {
        info.d(info.d_count - 1);
      }
      ros1::definition_starts_with_header(m.connection->message_definition);
    }
  }
  return 0;
}
