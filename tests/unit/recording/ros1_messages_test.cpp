// ROS 1 message decoders against messages serialized field by field from the .msg definitions
// (tests/common/ros1_serialize.hpp): values, views into the bytes, and malformed input (every
// truncation, trailing bytes, inconsistent clouds and images).

#include "drivers/recording/ros1_messages.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "tests/common/ros1_serialize.hpp"

namespace posed::testing {
namespace ros1_messages_test {

namespace ros1 = drivers::recording::ros1;
namespace ser = test::ros1;

TEST(Ros1Messages, ImuValuesAndHeader) {
  ser::ImuValues v;
  v.q_xyzw = {0.1, 0.2, 0.3, 0.9};
  v.w_radps = {0.01, -0.02, 0.5};
  v.a_mps2 = {0.3, -0.1, 9.81};
  const auto bytes = ser::imu(42, 1'628'000'123'456'789'000, "imu_link", v);
  ros1::Imu imu;
  ASSERT_EQ(ros1::decode_imu(bytes, imu), ros1::Ros1Status::kOk);
  EXPECT_EQ(imu.header.seq, 42u);
  EXPECT_EQ(imu.header.stamp_ns, 1'628'000'123'456'789'000);
  EXPECT_EQ(imu.header.frame_id, "imu_link");
  EXPECT_EQ(imu.orientation_xyzw, v.q_xyzw);
  EXPECT_EQ(imu.angular_velocity_radps, v.w_radps);
  EXPECT_EQ(imu.linear_acceleration_mps2, v.a_mps2);
  EXPECT_EQ(imu.angular_velocity_covariance[4], 1e-4);
  // The frame id is a view into the message, not a copy.
  EXPECT_GE(reinterpret_cast<const std::byte*>(imu.header.frame_id.data()), bytes.data());
  EXPECT_LT(reinterpret_cast<const std::byte*>(imu.header.frame_id.data()),
            bytes.data() + bytes.size());
  ros1::Header h;
  EXPECT_EQ(ros1::decode_header(bytes, h), ros1::Ros1Status::kOk);
  EXPECT_EQ(h.stamp_ns, imu.header.stamp_ns);
}

TEST(Ros1Messages, EveryTruncationIsAStatusAndExtraBytesAreNoted) {
  const auto imu = ser::imu(1, 5'000'000'000, "imu", {});
  ros1::Imu out;
  for (std::size_t n = 0; n < imu.size(); ++n) {
    EXPECT_EQ(ros1::decode_imu(std::span(imu.data(), n), out), ros1::Ros1Status::kTruncated) << n;
  }
  auto longer = imu;
  longer.push_back(std::byte{0});
  EXPECT_EQ(ros1::decode_imu(longer, out), ros1::Ros1Status::kTrailingBytes);

  std::vector<std::byte> data(3 * ser::kVelodynePointStep);
  const auto cloud = ser::point_cloud2(1, 1, "velodyne", 1, 3, ser::velodyne_fields(),
                                       ser::kVelodynePointStep, data);
  ros1::PointCloud2 pc;
  for (std::size_t n = 0; n < cloud.size(); ++n) {
    EXPECT_EQ(ros1::decode_point_cloud2(std::span(cloud.data(), n), pc),
              ros1::Ros1Status::kTruncated)
        << n;
  }
}

TEST(Ros1Messages, PointCloud2FieldsAndPoints) {
  std::vector<std::byte> data(2 * ser::kVelodynePointStep);
  const float x = 1.5f, t = 0.05f;
  const std::uint16_t ring = 17;
  std::memcpy(data.data() + ser::kVelodynePointStep + 0, &x, 4);
  std::memcpy(data.data() + ser::kVelodynePointStep + 20, &ring, 2);
  std::memcpy(data.data() + ser::kVelodynePointStep + 24, &t, 4);
  const auto bytes = ser::point_cloud2(9, 7'000'000'001, "velodyne", 1, 2, ser::velodyne_fields(),
                                       ser::kVelodynePointStep, data);
  ros1::PointCloud2 pc;
  ASSERT_EQ(ros1::decode_point_cloud2(bytes, pc), ros1::Ros1Status::kOk);
  EXPECT_EQ(pc.header.stamp_ns, 7'000'000'001);
  EXPECT_EQ(pc.point_count(), 2u);
  EXPECT_EQ(pc.field_count, 6u);
  ASSERT_NE(pc.field("ring"), nullptr);
  EXPECT_EQ(pc.field("ring")->datatype, static_cast<std::uint8_t>(ros1::PointFieldType::kUint16));
  EXPECT_EQ(pc.field("time")->offset, 24u);
  EXPECT_EQ(pc.field("rgb"), nullptr);
  const auto p1 = pc.point(1);
  ASSERT_EQ(p1.size(), ser::kVelodynePointStep);
  float got_x = 0;
  std::memcpy(&got_x, p1.data(), 4);
  EXPECT_EQ(got_x, x);
  EXPECT_EQ(p1.data(), bytes.data() + (bytes.size() - 1 - data.size()) + ser::kVelodynePointStep)
      << "points are views into the message";
}

TEST(Ros1Messages, InconsistentCloudsAreRejected) {
  std::vector<std::byte> data(2 * ser::kVelodynePointStep);
  ros1::PointCloud2 pc;
  // Fewer bytes than width x point_step.
  auto short_data = data;
  short_data.resize(data.size() - 1);
  EXPECT_EQ(ros1::decode_point_cloud2(ser::point_cloud2(1, 1, "v", 1, 2, ser::velodyne_fields(),
                                                        ser::kVelodynePointStep, short_data),
                                      pc),
            ros1::Ros1Status::kInconsistent);
  // A field that runs past the point.
  auto fields = ser::velodyne_fields();
  fields.push_back({"beyond", 30, 7, 1});
  EXPECT_EQ(ros1::decode_point_cloud2(
                ser::point_cloud2(1, 1, "v", 1, 2, fields, ser::kVelodynePointStep, data), pc),
            ros1::Ros1Status::kInconsistent);
  // An unknown datatype.
  fields = ser::velodyne_fields();
  fields[0].datatype = 42;
  EXPECT_EQ(ros1::decode_point_cloud2(
                ser::point_cloud2(1, 1, "v", 1, 2, fields, ser::kVelodynePointStep, data), pc),
            ros1::Ros1Status::kInconsistent);
  // More fields than the decoder keeps.
  std::vector<ser::Field> many;
  for (std::uint32_t i = 0; i < ros1::PointCloud2::kMaxFields + 1; ++i) {
    many.push_back({"f" + std::to_string(i), 0, 2, 1});
  }
  EXPECT_EQ(ros1::decode_point_cloud2(ser::point_cloud2(1, 1, "v", 1, 2, many, 16, data), pc),
            ros1::Ros1Status::kTooManyFields);
}

TEST(Ros1Messages, ImageAndCompressedImage) {
  ser::Serializer s;
  std::vector<std::byte> pixels(4 * 3 * 2);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::byte>(i);
  s.header(3, 2'000'000'000, "camera").u32(2).u32(4).string("rgb8").u8(0).u32(12).blob(pixels);
  ros1::Image image;
  ASSERT_EQ(ros1::decode_image(s.bytes, image), ros1::Ros1Status::kOk);
  EXPECT_EQ(image.width, 4u);
  EXPECT_EQ(image.height, 2u);
  EXPECT_EQ(image.encoding, "rgb8");
  EXPECT_EQ(image.step, 12u);
  ASSERT_EQ(image.data.size(), pixels.size());
  EXPECT_EQ(std::memcmp(image.data.data(), pixels.data(), pixels.size()), 0);
  EXPECT_EQ(ros1::camera_wire_format(image), drivers::camera::WireFormat::kRgb8);

  // step x height larger than the data: inconsistent.
  ser::Serializer bad;
  bad.header(3, 2, "camera").u32(3).u32(4).string("rgb8").u8(0).u32(12).blob(pixels);
  EXPECT_EQ(ros1::decode_image(bad.bytes, image), ros1::Ros1Status::kInconsistent);

  ser::Serializer c;
  c.header(4, 5, "thermal").string("jpeg").blob(pixels);
  ros1::CompressedImage ci;
  ASSERT_EQ(ros1::decode_compressed_image(c.bytes, ci), ros1::Ros1Status::kOk);
  EXPECT_EQ(ci.format, "jpeg");
  EXPECT_EQ(ci.data.size(), pixels.size());
}

TEST(Ros1Messages, CameraWireFormatsFollowImageEncodings) {
  using drivers::camera::WireFormat;
  ros1::Image i;
  const auto fmt = [&](std::string_view e, bool big_endian = false) {
    i.encoding = e;
    i.is_bigendian = big_endian;
    return ros1::camera_wire_format(i);
  };
  EXPECT_EQ(fmt("bgr8"), WireFormat::kBgr8);
  EXPECT_EQ(fmt("mono8"), WireFormat::kY8);
  EXPECT_EQ(fmt("mono16"), WireFormat::kY16);
  EXPECT_EQ(fmt("16UC1"), WireFormat::kZ16);
  EXPECT_EQ(fmt("yuv422"), WireFormat::kUyvy);  // ROS's yuv422 is UYVY
  EXPECT_EQ(fmt("yuv422_yuy2"), WireFormat::kYuyv);
  EXPECT_EQ(fmt("mono16", true), std::nullopt);
  EXPECT_EQ(fmt("32FC1"), std::nullopt);
}

TEST(Ros1Messages, CameraInfo) {
  ser::Serializer s;
  const std::array<double, 9> K{600, 0, 320, 0, 601, 240, 0, 0, 1};
  const std::array<double, 9> R{1, 0, 0, 0, 1, 0, 0, 0, 1};
  const std::array<double, 12> P{600, 0, 320, 0, 0, 601, 240, 0, 0, 0, 1, 0};
  s.header(1, 9, "cam").u32(480).u32(640).string("plumb_bob");
  s.u32(5).f64(0.1).f64(-0.2).f64(0.001).f64(0.002).f64(0.05);
  s.f64s(K).f64s(R).f64s(P).u32(1).u32(1).u32(0).u32(0).u32(0).u32(0).u8(0);
  ros1::CameraInfo info;
  ASSERT_EQ(ros1::decode_camera_info(s.bytes, info), ros1::Ros1Status::kOk);
  EXPECT_EQ(info.width, 640u);
  EXPECT_EQ(info.height, 480u);
  EXPECT_EQ(info.distortion_model, "plumb_bob");
  ASSERT_EQ(info.d_count, 5u);
  EXPECT_EQ(info.d(1), -0.2);
  EXPECT_EQ(info.d(4), 0.05);
  EXPECT_EQ(info.K, K);
  EXPECT_EQ(info.P, P);
  EXPECT_EQ(info.binning_x, 1u);
  // A distortion count larger than the message is a truncation, not an overflow.
  ser::Serializer huge;
  huge.header(1, 9, "cam").u32(480).u32(640).string("plumb_bob").u32(0x40000000);
  EXPECT_EQ(ros1::decode_camera_info(huge.bytes, info), ros1::Ros1Status::kTruncated);
}

TEST(Ros1Messages, WhetherADefinitionStartsWithAHeader) {
  EXPECT_TRUE(ros1::definition_starts_with_header(ser::kImuDefinition));
  EXPECT_TRUE(ros1::definition_starts_with_header(ser::kPointCloud2Definition));
  EXPECT_FALSE(ros1::definition_starts_with_header(ser::kStringDefinition));
  EXPECT_TRUE(ros1::definition_starts_with_header(
      "# comment\n\n  uint8 MODE_A = 1  # a constant\nstd_msgs/Header header\nfloat32 x\n"));
  EXPECT_FALSE(ros1::definition_starts_with_header("float32 x\nHeader header\n"));
  EXPECT_FALSE(
      ros1::definition_starts_with_header("==============\nMSG: std_msgs/Header\nuint32 seq\n"));
  EXPECT_FALSE(ros1::definition_starts_with_header(""));
}

}  // namespace ros1_messages_test
}  // namespace posed::testing
