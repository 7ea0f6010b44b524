#include "drivers/recording/ros1_messages.hpp"

#include <bit>
#include <cstring>

namespace posed::drivers::recording::ros1 {

static_assert(std::endian::native == std::endian::little,
              "ROS 1 serialization is little-endian; the loads below assume a little-endian host");

std::string_view to_string(Ros1Status s) {
  switch (s) {
    case Ros1Status::kOk:
      return "ok";
    case Ros1Status::kTruncated:
      return "truncated";
    case Ros1Status::kTrailingBytes:
      return "trailing bytes";
    case Ros1Status::kInconsistent:
      return "inconsistent fields";
    case Ros1Status::kTooManyFields:
      return "too many point fields";
  }
  return "unknown";
}

namespace {

/// Reads fields front to back; the first read past the end sets !ok() and every later read
/// returns zeros, so a decoder checks once at the end.
class Cursor {
 public:
  explicit Cursor(std::span<const std::byte> bytes) : bytes_(bytes) {}

  bool ok() const { return ok_; }
  std::size_t remaining() const { return ok_ ? bytes_.size() - pos_ : 0; }

  template <class T>
  T pod() {
    T v{};
    if (!ok_ || bytes_.size() - pos_ < sizeof(T)) {
      ok_ = false;
      return v;
    }
    std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::uint8_t u8() { return pod<std::uint8_t>(); }
  std::uint32_t u32() { return pod<std::uint32_t>(); }
  double f64() { return pod<double>(); }
  std::int64_t time_ns() {
    const std::uint32_t sec = u32();
    const std::uint32_t nsec = u32();
    return static_cast<std::int64_t>(sec) * 1'000'000'000 + nsec;
  }
  std::span<const std::byte> take(std::size_t n) {
    if (!ok_ || bytes_.size() - pos_ < n) {
      ok_ = false;
      return {};
    }
    const auto s = bytes_.subspan(pos_, n);
    pos_ += n;
    return s;
  }
  /// u32 length + bytes (string, uint8[])
  std::span<const std::byte> blob() { return take(u32()); }
  std::string_view string() {
    const auto b = blob();
    return {reinterpret_cast<const char*>(b.data()), b.size()};
  }
  template <std::size_t N>
  void f64s(std::array<double, N>& out) {
    for (double& v : out) v = f64();
  }

 private:
  std::span<const std::byte> bytes_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

void read_header(Cursor& c, Header& h) {
  h.seq = c.u32();
  h.stamp_ns = c.time_ns();
  h.frame_id = c.string();
}

Ros1Status finish(const Cursor& c) {
  if (!c.ok()) return Ros1Status::kTruncated;
  return c.remaining() == 0 ? Ros1Status::kOk : Ros1Status::kTrailingBytes;
}

}  // namespace

std::size_t point_field_size(std::uint8_t datatype) {
  switch (static_cast<PointFieldType>(datatype)) {
    case PointFieldType::kInt8:
    case PointFieldType::kUint8:
      return 1;
    case PointFieldType::kInt16:
    case PointFieldType::kUint16:
      return 2;
    case PointFieldType::kInt32:
    case PointFieldType::kUint32:
    case PointFieldType::kFloat32:
      return 4;
    case PointFieldType::kFloat64:
      return 8;
  }
  return 0;
}

const PointField* PointCloud2::field(std::string_view name) const {
  for (std::size_t i = 0; i < field_count; ++i) {
    if (fields[i].name == name) return &fields[i];
  }
  return nullptr;
}

std::span<const std::byte> PointCloud2::point(std::size_t i) const {
  const std::size_t row = width == 0 ? 0 : i / width;
  const std::size_t col = width == 0 ? 0 : i % width;
  return data.subspan(row * row_step + col * point_step, point_step);
}

double CameraInfo::d(std::size_t i) const {
  double v = 0;
  if (i < d_count) std::memcpy(&v, d_bytes.data() + i * sizeof(double), sizeof v);
  return v;
}

Ros1Status decode_header(std::span<const std::byte> bytes, Header& out) {
  // A Header is a prefix of the messages that start with one: bytes after it are not an error.
  Cursor c(bytes);
  read_header(c, out);
  return c.ok() ? Ros1Status::kOk : Ros1Status::kTruncated;
}

Ros1Status decode_point_cloud2(std::span<const std::byte> bytes, PointCloud2& out) {
  Cursor c(bytes);
  read_header(c, out.header);
  out.height = c.u32();
  out.width = c.u32();
  const std::uint32_t n_fields = c.u32();
  out.field_count = 0;
  for (std::uint32_t i = 0; i < n_fields && c.ok(); ++i) {
    PointField f;
    f.name = c.string();
    f.offset = c.u32();
    f.datatype = c.u8();
    f.count = c.u32();
    if (!c.ok()) break;
    if (out.field_count == PointCloud2::kMaxFields) return Ros1Status::kTooManyFields;
    out.fields[out.field_count++] = f;
  }
  out.is_bigendian = c.u8() != 0;
  out.point_step = c.u32();
  out.row_step = c.u32();
  out.data = c.blob();
  out.is_dense = c.u8() != 0;
  const Ros1Status s = finish(c);
  if (s != Ros1Status::kOk) return s;
  // Every point must lie inside `data`, and every field inside its point.
  const std::uint64_t row_bytes = std::uint64_t{out.width} * out.point_step;
  if (out.row_step < row_bytes ||
      std::uint64_t{out.row_step} * out.height > out.data.size() + (out.row_step - row_bytes)) {
    return Ros1Status::kInconsistent;
  }
  for (std::size_t i = 0; i < out.field_count; ++i) {
    const PointField& f = out.fields[i];
    const std::uint64_t size = point_field_size(f.datatype);
    if (size == 0 || std::uint64_t{f.offset} + size * f.count > out.point_step) {
      return Ros1Status::kInconsistent;
    }
  }
  return Ros1Status::kOk;
}

Ros1Status decode_image(std::span<const std::byte> bytes, Image& out) {
  Cursor c(bytes);
  read_header(c, out.header);
  out.height = c.u32();
  out.width = c.u32();
  out.encoding = c.string();
  out.is_bigendian = c.u8() != 0;
  out.step = c.u32();
  out.data = c.blob();
  const Ros1Status s = finish(c);
  if (s != Ros1Status::kOk) return s;
  if (std::uint64_t{out.step} * out.height > out.data.size()) return Ros1Status::kInconsistent;
  return Ros1Status::kOk;
}

Ros1Status decode_compressed_image(std::span<const std::byte> bytes, CompressedImage& out) {
  Cursor c(bytes);
  read_header(c, out.header);
  out.format = c.string();
  out.data = c.blob();
  return finish(c);
}

Ros1Status decode_imu(std::span<const std::byte> bytes, Imu& out) {
  Cursor c(bytes);
  read_header(c, out.header);
  c.f64s(out.orientation_xyzw);
  c.f64s(out.orientation_covariance);
  c.f64s(out.angular_velocity_radps);
  c.f64s(out.angular_velocity_covariance);
  c.f64s(out.linear_acceleration_mps2);
  c.f64s(out.linear_acceleration_covariance);
  return finish(c);
}

Ros1Status decode_camera_info(std::span<const std::byte> bytes, CameraInfo& out) {
  Cursor c(bytes);
  read_header(c, out.header);
  out.height = c.u32();
  out.width = c.u32();
  out.distortion_model = c.string();
  const std::uint32_t n = c.u32();
  // Checked against what is left before multiplying: n is untrusted.
  if (n > c.remaining() / sizeof(double)) return Ros1Status::kTruncated;
  out.d_count = n;
  out.d_bytes = c.take(std::size_t{n} * sizeof(double));
  c.f64s(out.K);
  c.f64s(out.R);
  c.f64s(out.P);
  out.binning_x = c.u32();
  out.binning_y = c.u32();
  out.roi_x_offset = c.u32();
  out.roi_y_offset = c.u32();
  out.roi_height = c.u32();
  out.roi_width = c.u32();
  out.roi_do_rectify = c.u8() != 0;
  return finish(c);
}

bool definition_starts_with_header(std::string_view def) {
  std::size_t pos = 0;
  while (pos < def.size()) {
    std::size_t end = def.find('\n', pos);
    if (end == std::string_view::npos) end = def.size();
    std::string_view line = def.substr(pos, end - pos);
    pos = end + 1;
    if (const auto hash = line.find('#'); hash != std::string_view::npos) {
      line = line.substr(0, hash);
    }
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos) continue;
    line = line.substr(first);
    // The dependencies gendeps appends start with a line of '='; the first field precedes them.
    if (line.rfind("==", 0) == 0) return false;
    const auto space = line.find_first_of(" \t");
    if (space == std::string_view::npos) return false;
    const std::string_view type = line.substr(0, space);
    std::string_view rest = line.substr(space);
    rest = rest.substr(std::min(rest.size(), rest.find_first_not_of(" \t")));
    // A constant ("uint8 FOO=1") is not a field.
    if (rest.find('=') != std::string_view::npos) continue;
    return type == "Header" || type == "std_msgs/Header";
  }
  return false;
}

std::optional<camera::WireFormat> camera_wire_format(const Image& image) {
  using camera::WireFormat;
  const std::string_view e = image.encoding;
  if (e == "rgb8") return WireFormat::kRgb8;
  if (e == "bgr8") return WireFormat::kBgr8;
  if (e == "mono8" || e == "8UC1") return WireFormat::kY8;
  // ROS's yuv422 is UYVY (sensor_msgs/image_encodings.h: "YUV422" = UYVY), yuv422_yuy2 YUYV.
  if (e == "yuv422" || e == "uyvy") return WireFormat::kUyvy;
  if (e == "yuv422_yuy2" || e == "yuyv") return WireFormat::kYuyv;
  // posed's 16-bit kernels read little-endian samples.
  if (image.is_bigendian) return std::nullopt;
  if (e == "mono16") return WireFormat::kY16;
  if (e == "16UC1") return WireFormat::kZ16;
  return std::nullopt;
}

}  // namespace posed::drivers::recording::ros1
