#pragma once
// Pure decoders of ROS 1 serialization (wiki.ros.org/msg, "Serialization"; little-endian,
// strings and variable arrays as u32 length + elements, fixed arrays without length, time as
// sec u32 + nsec u32) for the message types posed reads from bags: std_msgs/Header,
// sensor_msgs/PointCloud2 (+ PointField), Image, CompressedImage, Imu and CameraInfo.
//
// They never throw and never allocate: strings and blobs are views/spans into the message bytes,
// which must outlive the decoded struct. A malformed message is a status; nothing is read
// outside the bytes. A message with bytes left over after its last field is kTrailingBytes: its
// type is not the one the decoder was asked for (the md5sums would differ).

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "drivers/camera/pixel_formats.hpp"

namespace posed::drivers::recording::ros1 {

enum class Ros1Status : std::uint8_t {
  kOk,
  kTruncated,      ///< the bytes end inside a field
  kTrailingBytes,  ///< bytes left after the last field (another type, or another version)
  kInconsistent,   ///< fields disagree (data shorter than step x height, a field past point_step)
  kTooManyFields,  ///< a PointCloud2 with more fields than PointCloud2::kMaxFields
};

std::string_view to_string(Ros1Status s);

/// std_msgs/Header.
struct Header {
  std::uint32_t seq = 0;
  /// header.stamp (sec, nsec) as ns; the clock is the publisher's (usually ROS time) [ns]
  std::int64_t stamp_ns = 0;
  std::string_view frame_id;
};

/// sensor_msgs/PointField datatypes.
enum class PointFieldType : std::uint8_t {
  kInt8 = 1,
  kUint8 = 2,
  kInt16 = 3,
  kUint16 = 4,
  kInt32 = 5,
  kUint32 = 6,
  kFloat32 = 7,
  kFloat64 = 8,
};
/// bytes of one element; 0 for an unknown datatype
std::size_t point_field_size(std::uint8_t datatype);

/// sensor_msgs/PointField.
struct PointField {
  std::string_view name;
  std::uint32_t offset = 0;  ///< from the start of the point [B]
  std::uint8_t datatype = 0;
  std::uint32_t count = 1;  ///< elements
};

/// sensor_msgs/PointCloud2.
struct PointCloud2 {
  static constexpr std::size_t kMaxFields = 32;
  Header header;
  std::uint32_t height = 0;  ///< rows; 1 for an unordered cloud
  std::uint32_t width = 0;   ///< points per row
  std::array<PointField, kMaxFields> fields{};
  std::size_t field_count = 0;
  bool is_bigendian = false;
  std::uint32_t point_step = 0;  ///< [B]
  std::uint32_t row_step = 0;    ///< [B]
  std::span<const std::byte> data;
  bool is_dense = false;

  /// The field called `name`, or nullptr.
  const PointField* field(std::string_view name) const;
  std::size_t point_count() const { return std::size_t{width} * height; }
  /// Point `i` (row-major) as bytes of point_step.
  std::span<const std::byte> point(std::size_t i) const;
};

/// sensor_msgs/Image.
struct Image {
  Header header;
  std::uint32_t height = 0;  ///< [px]
  std::uint32_t width = 0;   ///< [px]
  /// "rgb8", "bgr8", "mono8", "mono16", "16UC1", "yuv422", ... (sensor_msgs/image_encodings.h)
  std::string_view encoding;
  bool is_bigendian = false;
  std::uint32_t step = 0;  ///< bytes per row [B]
  std::span<const std::byte> data;
};

/// sensor_msgs/CompressedImage.
struct CompressedImage {
  Header header;
  std::string_view format;  ///< "jpeg", "png", "rgb8; jpeg compressed bgr8", ...
  std::span<const std::byte> data;
};

/// sensor_msgs/Imu, in the frame of header.frame_id.
struct Imu {
  Header header;
  std::array<double, 4> orientation_xyzw{};
  /// row-major; element 0 = -1 means "no orientation estimate" (REP-145)
  std::array<double, 9> orientation_covariance{};
  std::array<double, 3> angular_velocity_radps{};  ///< [rad/s]
  std::array<double, 9> angular_velocity_covariance{};
  /// specific force (what an accelerometer measures: +g up at rest) [m/s^2]
  std::array<double, 3> linear_acceleration_mps2{};
  std::array<double, 9> linear_acceleration_covariance{};
};

/// sensor_msgs/CameraInfo.
struct CameraInfo {
  Header header;
  std::uint32_t height = 0;           ///< [px]
  std::uint32_t width = 0;            ///< [px]
  std::string_view distortion_model;  ///< "plumb_bob", "rational_polynomial", "equidistant"
  /// D: the distortion coefficients, float64 little-endian, `d_count` of them
  std::span<const std::byte> d_bytes;
  std::size_t d_count = 0;
  std::array<double, 9> K{};   ///< intrinsics, row-major: fx 0 cx; 0 fy cy; 0 0 1 [px]
  std::array<double, 9> R{};   ///< rectification rotation, row-major
  std::array<double, 12> P{};  ///< projection, row-major 3x4 [px]
  std::uint32_t binning_x = 0, binning_y = 0;
  std::uint32_t roi_x_offset = 0, roi_y_offset = 0, roi_height = 0, roi_width = 0;  ///< [px]
  bool roi_do_rectify = false;

  /// Distortion coefficient `i` (< d_count).
  double d(std::size_t i) const;
};

Ros1Status decode_header(std::span<const std::byte> bytes, Header& out);
Ros1Status decode_point_cloud2(std::span<const std::byte> bytes, PointCloud2& out);
Ros1Status decode_image(std::span<const std::byte> bytes, Image& out);
Ros1Status decode_compressed_image(std::span<const std::byte> bytes, CompressedImage& out);
Ros1Status decode_imu(std::span<const std::byte> bytes, Imu& out);
Ros1Status decode_camera_info(std::span<const std::byte> bytes, CameraInfo& out);

/// Whether a message type's first field is a std_msgs/Header, from its definition text (the
/// bag's message_definition): true for "Header header" or "std_msgs/Header header" as the first
/// field, comments and constants aside. Such a message's header.stamp is its publish time.
bool definition_starts_with_header(std::string_view message_definition);

/// The camera wire format of an Image's pixels, so drivers/camera's kernels decode them:
/// rgb8, bgr8, mono8/8UC1 (Y8), mono16 (Y16), 16UC1 (Z16 depth), yuv422 (UYVY), yuv422_yuy2
/// (YUYV). nullopt for other encodings and for big-endian 16-bit data.
std::optional<camera::WireFormat> camera_wire_format(const Image& image);

}  // namespace posed::drivers::recording::ros1
