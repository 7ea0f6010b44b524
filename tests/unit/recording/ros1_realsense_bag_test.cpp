// The ROS 1 bag reader and message decoders on a real librealsense recording (LZ4 chunks, a D435
// at 640x480: depth and colour frames, camera_info, stream info, options and per-frame metadata;
// ../shared/realdata/realsense_d435/). Expectations come from the file itself: the stream info
// names each stream's encoding and rate, the options topic the depth unit, and the per-frame
// metadata the hardware timestamps, so nothing below is a number copied from a viewer.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "drivers/camera/pixel_formats.hpp"
#include "drivers/recording/ros1_bag_reader.hpp"
#include "drivers/recording/ros1_messages.hpp"
#include "tests/common/realdata.hpp"

namespace posed::testing {
namespace ros1_realsense_bag_test {

namespace ros1 = drivers::recording::ros1;
namespace camera = drivers::camera;

constexpr const char* kBag = "realsense_d435/single_depth_color_640x480.bag";
constexpr const char* kDepthTopic = "/device_0/sensor_0/Depth_0/image/data";
constexpr const char* kColorTopic = "/device_0/sensor_1/Color_0/image/data";

/// Everything the bag holds, decoded once per test.
struct BagContents {
  struct Message {
    std::string topic, type;
    std::uint64_t receive_time_ns = 0;
    std::vector<std::byte> data;
  };
  std::vector<Message> messages;
  std::map<std::string, std::string> types;  // topic -> type
  std::map<std::string, std::uint64_t> counts;
  std::map<std::uint32_t, std::uint64_t> indexed_counts;
  std::map<std::uint32_t, std::string> topic_of_conn;
  bool indexed = false, complete = false;
  std::string compression;

  std::vector<const Message*> on(const std::string& topic) const {
    std::vector<const Message*> out;
    for (const auto& m : messages) {
      if (m.topic == topic) out.push_back(&m);
    }
    return out;
  }
};

BagContents read_bag(const std::string& path, bool use_index) {
  BagContents c;
  ros1::BagReader reader;
  std::string error;
  ros1::BagReaderOptions options;
  options.use_index = use_index;
  EXPECT_TRUE(reader.open(path, error, options)) << error;
  ros1::BagMessage m;
  while (reader.next(m)) {
    c.messages.push_back({m.connection->topic, m.connection->type, m.receive_time_ns,
                          std::vector<std::byte>(m.data.begin(), m.data.end())});
    c.types[m.connection->topic] = m.connection->type;
    ++c.counts[m.connection->topic];
  }
  c.indexed = reader.indexed();
  c.complete = reader.complete();
  c.indexed_counts = reader.indexed_counts();
  for (const auto& [id, conn] : reader.connections()) c.topic_of_conn[id] = conn.topic;
  if (!reader.chunks().empty()) c.compression = reader.chunks().front().compression;
  return c;
}

/// std_msgs/String and diagnostic_msgs/KeyValue are u32-length strings.
std::string ros_string(const std::vector<std::byte>& d, std::size_t& pos) {
  std::uint32_t n = 0;
  if (d.size() < pos + 4) return {};
  std::memcpy(&n, d.data() + pos, 4);
  pos += 4;
  if (d.size() < pos + n) return {};
  std::string s(reinterpret_cast<const char*>(d.data() + pos), n);
  pos += n;
  return s;
}

/// realsense_msgs/StreamInfo: uint32 fps, string encoding, bool is_recommended.
struct StreamInfo {
  std::uint32_t fps = 0;
  std::string encoding;
};
StreamInfo stream_info(const BagContents& bag, const std::string& info_topic) {
  const auto msgs = bag.on(info_topic);
  EXPECT_EQ(msgs.size(), 1u) << info_topic;
  StreamInfo s;
  if (msgs.empty()) return s;
  std::memcpy(&s.fps, msgs[0]->data.data(), 4);
  std::size_t pos = 4;
  s.encoding = ros_string(msgs[0]->data, pos);
  return s;
}

/// The per-frame metadata (diagnostic_msgs/KeyValue) that follows each image, in order.
std::vector<std::map<std::string, std::string>> frame_metadata(const BagContents& bag,
                                                               const std::string& topic) {
  std::vector<std::map<std::string, std::string>> frames;
  for (const auto* m : bag.on(topic)) {
    std::size_t pos = 0;
    const std::string key = ros_string(m->data, pos);
    const std::string value = ros_string(m->data, pos);
    if (key == "system_time" || frames.empty()) frames.emplace_back();  // first key of a frame
    frames.back()[key] = value;
  }
  return frames;
}

TEST(RealsenseBag, TopicsTypesAndCountsAgreeWithTheIndexAndASequentialScan) {
  POSED_REQUIRE_REALDATA(path, kBag);
  const BagContents indexed = read_bag(path, true);
  const BagContents scanned = read_bag(path, false);
  EXPECT_TRUE(indexed.indexed);
  EXPECT_TRUE(indexed.complete);
  EXPECT_TRUE(scanned.complete);
  EXPECT_EQ(indexed.compression, "lz4");
  // The index's per-connection counts are what was delivered.
  std::map<std::string, std::uint64_t> from_index;
  for (const auto& [conn, n] : indexed.indexed_counts)
    from_index[indexed.topic_of_conn.at(conn)] += n;
  EXPECT_EQ(from_index, indexed.counts);
  EXPECT_EQ(scanned.counts, indexed.counts);
  EXPECT_EQ(scanned.messages.size(), indexed.messages.size());
  // The same messages both ways (their order differs where chunks overlap in time).
  auto key = [](const BagContents::Message& m) {
    return std::make_tuple(m.receive_time_ns, m.topic, m.data);
  };
  std::vector<decltype(key(indexed.messages[0]))> a, b;
  for (const auto& m : indexed.messages) a.push_back(key(m));
  for (const auto& m : scanned.messages) b.push_back(key(m));
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_TRUE(a == b);
  // Indexed reading is in receive-time order.
  for (std::size_t i = 1; i < indexed.messages.size(); ++i) {
    EXPECT_LE(indexed.messages[i - 1].receive_time_ns, indexed.messages[i].receive_time_ns);
  }

  EXPECT_EQ(indexed.types.at(kDepthTopic), "sensor_msgs/Image");
  EXPECT_EQ(indexed.types.at(kColorTopic), "sensor_msgs/Image");
  EXPECT_EQ(indexed.types.at("/device_0/sensor_0/Depth_0/info/camera_info"),
            "sensor_msgs/CameraInfo");
  EXPECT_EQ(indexed.types.at("/device_0/sensor_1/Color_0/info/camera_info"),
            "sensor_msgs/CameraInfo");
  EXPECT_EQ(indexed.types.at("/file_version"), "std_msgs/UInt32");
  EXPECT_GE(indexed.counts.at(kDepthTopic), 1u);
  EXPECT_EQ(indexed.counts.at(kColorTopic), 1u);
}

TEST(RealsenseBag, ImagesMatchTheirStreamInfoCameraInfoAndMetadata) {
  POSED_REQUIRE_REALDATA(path, kBag);
  const BagContents bag = read_bag(path, true);
  struct Stream {
    const char* image_topic;
    const char* info_topic;
    const char* camera_info_topic;
    const char* metadata_topic;
  };
  for (const Stream& s : {Stream{kDepthTopic, "/device_0/sensor_0/Depth_0/info",
                                 "/device_0/sensor_0/Depth_0/info/camera_info",
                                 "/device_0/sensor_0/Depth_0/image/metadata"},
                          Stream{kColorTopic, "/device_0/sensor_1/Color_0/info",
                                 "/device_0/sensor_1/Color_0/info/camera_info",
                                 "/device_0/sensor_1/Color_0/image/metadata"}}) {
    SCOPED_TRACE(s.image_topic);
    const StreamInfo info = stream_info(bag, s.info_topic);
    const auto ci_msgs = bag.on(s.camera_info_topic);
    ASSERT_EQ(ci_msgs.size(), 1u);
    ros1::CameraInfo ci;
    ASSERT_EQ(ros1::decode_camera_info(ci_msgs[0]->data, ci), ros1::Ros1Status::kOk);
    EXPECT_EQ(ci.width, 640u);
    EXPECT_EQ(ci.height, 480u);
    // A pinhole matrix: fx, fy > 0, no skew, principal point inside the image, last row 0 0 1;
    // the D435's square pixels make fx and fy agree within a fraction of a percent.
    EXPECT_GT(ci.K[0], 0);
    EXPECT_NEAR(ci.K[4] / ci.K[0], 1.0, 0.01);
    EXPECT_EQ(ci.K[1], 0);
    EXPECT_GT(ci.K[2], 0);
    EXPECT_LT(ci.K[2], ci.width);
    EXPECT_GT(ci.K[5], 0);
    EXPECT_LT(ci.K[5], ci.height);
    EXPECT_EQ(ci.K[6], 0);
    EXPECT_EQ(ci.K[7], 0);
    EXPECT_EQ(ci.K[8], 1);
    // librealsense names its model; five coefficients either way.
    EXPECT_FALSE(ci.distortion_model.empty());
    EXPECT_EQ(ci.d_count, 5u);

    const auto images = bag.on(s.image_topic);
    const auto metadata = frame_metadata(bag, s.metadata_topic);
    ASSERT_EQ(metadata.size(), images.size());
    std::int64_t previous_stamp = 0;
    long previous_counter = -1;
    for (std::size_t k = 0; k < images.size(); ++k) {
      ros1::Image image;
      ASSERT_EQ(ros1::decode_image(images[k]->data, image), ros1::Ros1Status::kOk);
      EXPECT_EQ(image.width, ci.width);
      EXPECT_EQ(image.height, ci.height);
      EXPECT_EQ(image.encoding, info.encoding);
      ASSERT_TRUE(ros1::camera_wire_format(image).has_value()) << image.encoding;
      EXPECT_EQ(image.step, image.width * static_cast<std::uint32_t>(camera::wire_bytes_per_pixel(
                                              *ros1::camera_wire_format(image))));
      EXPECT_EQ(image.data.size(), std::size_t{image.step} * image.height);
      // header.stamp is the frame's hardware timestamp ("Frame Timestamp", µs) in ns.
      const auto& md = metadata[k];
      ASSERT_TRUE(md.count("Frame Timestamp"));
      EXPECT_EQ(md.at("timestamp_domain"), "Hardware Clock");
      EXPECT_EQ(image.header.stamp_ns, std::stoll(md.at("Frame Timestamp")) * 1000);
      const long counter = std::stol(md.at("Frame Counter"));
      if (k > 0) {
        // Consecutive frames, one frame period (1 / the stream's fps) apart within 1 %.
        EXPECT_EQ(counter, previous_counter + 1);
        const double period_s = static_cast<double>(image.header.stamp_ns - previous_stamp) * 1e-9;
        EXPECT_NEAR(period_s, 1.0 / info.fps, 0.01 / info.fps);
      }
      previous_stamp = image.header.stamp_ns;
      previous_counter = counter;
    }
  }
  EXPECT_EQ(stream_info(bag, "/device_0/sensor_1/Color_0/info").encoding, "rgb8");
}

float depth_unit_m(const BagContents& bag) {
  const auto v = bag.on("/device_0/sensor_0/option/Depth Units/value");  // std_msgs/Float32
  EXPECT_EQ(v.size(), 1u);
  float unit = 0;
  if (!v.empty()) std::memcpy(&unit, v[0]->data.data(), 4);
  return unit;
}

TEST(RealsenseBag, DepthFramesDecodeThroughTheZ16Path) {
  POSED_REQUIRE_REALDATA(path, kBag);
  const BagContents bag = read_bag(path, true);
  const float unit = depth_unit_m(bag);
  ASSERT_GT(unit, 0.f);
  for (const auto* m : bag.on(kDepthTopic)) {
    ros1::Image image;
    ASSERT_EQ(ros1::decode_image(m->data, image), ros1::Ros1Status::kOk);
    // librealsense publishes its Z16 depth stream as mono16: the Z16 kernel decodes it.
    std::vector<std::uint16_t> depth(std::size_t{image.width} * image.height);
    const camera::FrameView src{image.data, image.width, image.height, image.step,
                                camera::WireFormat::kZ16};
    ASSERT_EQ(camera::decoded_format(src.format), PixelFormat::kDepth16);
    ASSERT_EQ(camera::convert_frame(src, {std::as_writable_bytes(std::span(depth)), 0}),
              camera::ConvertStatus::kOk);
    // Bit-exact: little-endian samples in, host-order depth units out.
    std::size_t valid = 0;
    std::vector<std::uint16_t> nonzero;
    for (std::size_t i = 0; i < depth.size(); ++i) {
      std::uint16_t raw = 0;
      std::memcpy(&raw, image.data.data() + (i / image.width) * image.step + (i % image.width) * 2,
                  2);
      ASSERT_EQ(depth[i], raw) << i;
      if (raw != 0) {
        ++valid;
        nonzero.push_back(raw);
      }
    }
    // A stereo depth frame of a scene: most pixels have a depth (0 = no match), and the median
    // lies in the D435's working range (0.1 m .. 10 m, Intel's D400 datasheet).
    EXPECT_GT(static_cast<double>(valid) / static_cast<double>(depth.size()), 0.5);
    std::nth_element(nonzero.begin(),
                     nonzero.begin() + static_cast<std::ptrdiff_t>(nonzero.size() / 2),
                     nonzero.end());
    const double median_m = nonzero[nonzero.size() / 2] * static_cast<double>(unit);
    EXPECT_GT(median_m, 0.1);
    EXPECT_LT(median_m, 10.0);
  }
}

TEST(RealsenseBag, TheColourFrameDecodesThroughPixelFormats) {
  POSED_REQUIRE_REALDATA(path, kBag);
  const BagContents bag = read_bag(path, true);
  const auto frames = bag.on(kColorTopic);
  ASSERT_EQ(frames.size(), 1u);
  ros1::Image image;
  ASSERT_EQ(ros1::decode_image(frames[0]->data, image), ros1::Ros1Status::kOk);
  const auto format = ros1::camera_wire_format(image);
  ASSERT_EQ(format, camera::WireFormat::kRgb8);
  ASSERT_EQ(camera::decoded_format(*format), PixelFormat::kRgb8);
  std::vector<std::uint8_t> rgb(std::size_t{image.width} * image.height * 3);
  ASSERT_EQ(camera::convert_frame({image.data, image.width, image.height, image.step, *format},
                                  {std::as_writable_bytes(std::span(rgb)), 0}),
            camera::ConvertStatus::kOk);
  ASSERT_EQ(std::memcmp(rgb.data(), image.data.data(), rgb.size()), 0) << "rgb8 stays rgb8";
  // A real, exposed picture: neither black nor blown out, with texture and colour, and no
  // rows missing (every row has some variation).
  double sum = 0, sum_sq = 0;
  std::array<double, 3> channel_sum{};
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    sum += rgb[i];
    sum_sq += static_cast<double>(rgb[i]) * rgb[i];
    channel_sum[i % 3] += rgb[i];
  }
  const double n = static_cast<double>(rgb.size());
  const double mean = sum / n;
  const double stddev = std::sqrt(sum_sq / n - mean * mean);
  EXPECT_GT(mean, 20.0);
  EXPECT_LT(mean, 235.0);
  EXPECT_GT(stddev, 10.0);
  const auto [lo, hi] = std::minmax_element(channel_sum.begin(), channel_sum.end());
  EXPECT_GT(*hi - *lo, 0.0) << "a colour image, not grey";
  for (std::uint32_t row = 0; row < image.height; ++row) {
    const std::uint8_t* r = rgb.data() + std::size_t{row} * image.width * 3;
    const auto [mn, mx] = std::minmax_element(r, r + std::size_t{image.width} * 3);
    ASSERT_GT(*mx - *mn, 0) << "row " << row << " is flat";
  }
}

TEST(RealsenseBag, ReceiveTimesAndStampsAreOrdered) {
  POSED_REQUIRE_REALDATA(path, kBag);
  const BagContents bag = read_bag(path, true);
  // librealsense records receive times relative to the start of the recording; the images
  // follow their stream set-up (stream info, camera_info, options) in receive time.
  std::uint64_t setup_end = 0;
  for (const auto* m : bag.on("/device_0/sensor_0/Depth_0/info/camera_info")) {
    setup_end = std::max(setup_end, m->receive_time_ns);
  }
  std::uint64_t previous = 0;
  for (const auto* m : bag.on(kDepthTopic)) {
    EXPECT_GE(m->receive_time_ns, setup_end);
    EXPECT_GE(m->receive_time_ns, previous);
    previous = m->receive_time_ns;
  }
}

}  // namespace ros1_realsense_bag_test
}  // namespace posed::testing
