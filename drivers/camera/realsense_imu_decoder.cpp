#include "drivers/camera/realsense_imu_decoder.hpp"

#include <numbers>

#include "drivers/common/wire_format.hpp"

namespace posed::drivers::camera {
namespace {
constexpr double kStandardGravity = 9.80665;  // [m/s^2], librealsense's `gravity`
}  // namespace

RealsenseImuDecoder::RealsenseImuDecoder(std::string_view wire_format, RealsenseImuConfig config) {
  std::string_view prefix;
  std::string_view axis_stem;
  if (wire_format.substr(0, wire::kIioAccel3d.size()) == wire::kIioAccel3d) {
    prefix = wire::kIioAccel3d;
    axis_stem = "in_accel_";
    kind_ = MotionKind::kAccel;
    scale_ = config.accel_g_per_lsb * kStandardGravity;
  } else if (wire_format.substr(0, wire::kIioGyro3d.size()) == wire::kIioGyro3d) {
    prefix = wire::kIioGyro3d;
    axis_stem = "in_anglvel_";
    kind_ = MotionKind::kGyro;
    scale_ = config.gyro_deg_per_lsb * std::numbers::pi / 180.0;
  } else {
    error_ = "not a D4xx IIO wire format: '" + std::string(wire_format) + "'";
    return;
  }
  if (!parse_iio_layout(wire_format, prefix, layout_, error_)) return;
  if (layout_.record_bytes == 0) {  // decode() divides by it
    error_ = "wire format '" + std::string(wire_format) + "' gives empty records";
    return;
  }
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    axis_[i] = layout_.find(std::string(axis_stem) + axes[i]);
    if (axis_[i] == nullptr) {
      error_ = "wire format '" + std::string(wire_format) + "' has no " + std::string(axis_stem) +
               axes[i];
      return;
    }
  }
  timestamp_ = layout_.find("in_timestamp");
  if (config.align_to_depth_frame) {
    flip_[0] = -1.0;
    flip_[2] = -1.0;
  }
  valid_ = true;
}

std::size_t RealsenseImuDecoder::decode(std::span<const std::byte> bytes,
                                        std::span<D4xxMotionSample> out) {
  if (!valid_) {
    ++counters_.bad_chunks;
    return 0;
  }
  const std::size_t records = bytes.size() / layout_.record_bytes;
  counters_.partial_bytes += bytes.size() % layout_.record_bytes;
  const std::size_t n = std::min(records, out.size());
  for (std::size_t r = 0; r < n; ++r) {
    const std::byte* rec = bytes.data() + r * layout_.record_bytes;
    D4xxMotionSample& s = out[r];
    s.kind = kind_;
    s.device_stamp =
        DeviceTime::from_ns(timestamp_ != nullptr ? iio_element_value(rec, *timestamp_) : 0);
    for (int i = 0; i < 3; ++i) {
      s.xyz_depth[i] = flip_[i] * scale_ * static_cast<double>(iio_element_value(rec, *axis_[i]));
    }
  }
  counters_.samples += n;
  return n;
}

}  // namespace posed::drivers::camera
