#pragma once
// Test-only ROS 1 serialization (little-endian; strings and variable arrays as u32 length +
// elements; time as sec u32 + nsec u32) of the sensor_msgs types posed imports, written field by
// field from the .msg definitions, independently of drivers/recording/ros1_messages.cpp, plus
// the definitions and md5sums `rosbag` stores in a Connection record (definitions stripped of
// comments; the md5sums are the real ones of the full types).

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

namespace posed::test::ros1 {

class Serializer {
 public:
  template <class T>
  Serializer& pod(T v) {
    const auto* p = reinterpret_cast<const std::byte*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof v);
    return *this;
  }
  Serializer& u8(std::uint8_t v) { return pod(v); }
  Serializer& u32(std::uint32_t v) { return pod(v); }
  Serializer& f32(float v) { return pod(v); }
  Serializer& f64(double v) { return pod(v); }
  Serializer& time(std::int64_t ns) {
    u32(static_cast<std::uint32_t>(ns / 1'000'000'000));
    return u32(static_cast<std::uint32_t>(ns % 1'000'000'000));
  }
  Serializer& string(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size()));
    const auto* p = reinterpret_cast<const std::byte*>(s.data());
    bytes.insert(bytes.end(), p, p + s.size());
    return *this;
  }
  Serializer& blob(const std::vector<std::byte>& b) {
    u32(static_cast<std::uint32_t>(b.size()));
    bytes.insert(bytes.end(), b.begin(), b.end());
    return *this;
  }
  template <std::size_t N>
  Serializer& f64s(const std::array<double, N>& a) {
    for (double v : a) f64(v);
    return *this;
  }
  Serializer& header(std::uint32_t seq, std::int64_t stamp_ns, std::string_view frame_id) {
    u32(seq);
    time(stamp_ns);
    return string(frame_id);
  }

  std::vector<std::byte> bytes;
};

inline constexpr std::string_view kHeaderDefinition = "uint32 seq\ntime stamp\nstring frame_id\n";

inline constexpr std::string_view kImuMd5 = "6a62c6daae103f4ff57a132d6f95cec2";
inline const std::string kImuDefinition =
    std::string(
        "Header header\n"
        "geometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n"
        "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n"
        "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n"
        "================================================================================\n"
        "MSG: std_msgs/Header\n") +
    std::string(kHeaderDefinition) +
    "================================================================================\n"
    "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n"
    "================================================================================\n"
    "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n";

inline constexpr std::string_view kPointCloud2Md5 = "1158d486dd51d683ce2f1be655c3c181";
inline const std::string kPointCloud2Definition =
    std::string(
        "Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool is_bigendian\n"
        "uint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n"
        "================================================================================\n"
        "MSG: std_msgs/Header\n") +
    std::string(kHeaderDefinition) +
    "================================================================================\n"
    "MSG: sensor_msgs/PointField\n"
    "uint8 INT8    = 1\nuint8 UINT8   = 2\nuint8 INT16   = 3\nuint8 UINT16  = 4\n"
    "uint8 INT32   = 5\nuint8 UINT32  = 6\nuint8 FLOAT32 = 7\nuint8 FLOAT64 = 8\n"
    "string name\nuint32 offset\nuint8  datatype\nuint32 count\n";

inline constexpr std::string_view kImageMd5 = "060021388200f6f0f447d0fcd9c64743";
inline const std::string kImageDefinition =
    std::string(
        "Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n"
        "uint32 step\nuint8[] data\n"
        "================================================================================\n"
        "MSG: std_msgs/Header\n") +
    std::string(kHeaderDefinition);

inline std::vector<std::byte> image(std::uint32_t seq, std::int64_t stamp_ns,
                                    std::string_view frame_id, std::uint32_t height,
                                    std::uint32_t width, std::string_view encoding,
                                    const std::vector<std::byte>& pixels) {
  Serializer s;
  s.header(seq, stamp_ns, frame_id).u32(height).u32(width).string(encoding).u8(0);
  s.u32(height == 0 ? 0 : static_cast<std::uint32_t>(pixels.size() / height)).blob(pixels);
  return std::move(s.bytes);
}

inline constexpr std::string_view kStringMd5 = "992ce8a1687cec8c8bd883ec73ca41d1";
inline constexpr std::string_view kStringDefinition = "string data\n";

struct ImuValues {
  std::array<double, 4> q_xyzw{0, 0, 0, 1};
  std::array<double, 3> w_radps{};
  std::array<double, 3> a_mps2{};
};

inline std::vector<std::byte> imu(std::uint32_t seq, std::int64_t stamp_ns,
                                  std::string_view frame_id, const ImuValues& v) {
  Serializer s;
  s.header(seq, stamp_ns, frame_id).f64s(v.q_xyzw);
  std::array<double, 9> cov{};
  cov[0] = cov[4] = cov[8] = 1e-4;
  s.f64s(cov).f64s(v.w_radps).f64s(cov).f64s(v.a_mps2).f64s(cov);
  return std::move(s.bytes);
}

/// One PointCloud2 field as the message carries it.
struct Field {
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 7;  // FLOAT32
  std::uint32_t count = 1;
};

inline std::vector<std::byte> point_cloud2(std::uint32_t seq, std::int64_t stamp_ns,
                                           std::string_view frame_id, std::uint32_t height,
                                           std::uint32_t width, const std::vector<Field>& fields,
                                           std::uint32_t point_step,
                                           const std::vector<std::byte>& data,
                                           bool is_dense = true) {
  Serializer s;
  s.header(seq, stamp_ns, frame_id).u32(height).u32(width);
  s.u32(static_cast<std::uint32_t>(fields.size()));
  for (const Field& f : fields) s.string(f.name).u32(f.offset).u8(f.datatype).u32(f.count);
  s.u8(0).u32(point_step).u32(point_step * width).blob(data).u8(is_dense ? 1 : 0);
  return std::move(s.bytes);
}

/// velodyne_pointcloud's PointXYZIRT layout: x y z intensity (float32), ring (uint16), time
/// (float32 seconds from header.stamp); 22 B of fields, padded to 32 as PCL aligns the point.
inline std::vector<Field> velodyne_fields() {
  return {{"x", 0, 7, 1},          {"y", 4, 7, 1},     {"z", 8, 7, 1},
          {"intensity", 16, 7, 1}, {"ring", 20, 4, 1}, {"time", 24, 7, 1}};
}
inline constexpr std::uint32_t kVelodynePointStep = 32;

}  // namespace posed::test::ros1
