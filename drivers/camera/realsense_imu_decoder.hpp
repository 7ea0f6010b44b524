#pragma once
// D435i IMU samples from the raw IIO records of its hid-sensor-accel-3d / hid-sensor-gyro-3d
// devices (RealsenseImuSource, or a recording of it). Pure: no I/O, no allocation after
// construction, never throws; a bad layout or a trailing partial record is a counted status.
//
// Scaling and axes as librealsense applies them for the D435i (Bosch BMI055 behind HID):
// - accel: 1 LSB = 0.001 g, g = 9.80665 m/s^2 (src/proc/motion-transform.cpp,
//   acceleration_transform: accelerator_scale_factor = 0.001 * gravity);
// - gyro: 1 LSB = 0.1 deg/s by default, 0.003814697265625 deg/s in high-sensitivity mode
//   (motion-transform.cpp, unpack_gyro_axes / gyroscope_transform's gyro_scale_factor);
// - values keep only their significant bits (converter_16_bit: "data is valid at the lower 16
//   bits only"; here the scan type's realbits decide, so s32/32 kernels work unchanged);
// - axes: the IMU's are turned into the depth camera frame with diag(-1, 1, -1)
//   (src/ds/ds-motion-common.h, dm_v2_imu_calib_parser: D435i "_imu_2_depth_rot =
//   {{-1,0,0},{0,1,0},{0,0,-1}}"), i.e. x right, y down, z forward as the depth image.
// - timestamp: the in_timestamp element [ns] the kernel stores with each scan; for the D435i
//   the HID report carries the device's own timestamp, which hid-sensor converts to ns
//   (librealsense reads it at record offset 16 and divides by 1000 to get firmware us).

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "core/time.hpp"
#include "drivers/camera/iio_scan.hpp"

namespace posed::drivers::camera {

enum class MotionKind : std::uint8_t { kAccel, kGyro };

/// One accelerometer or gyro sample of the D435i.
struct D4xxMotionSample {
  MotionKind kind = MotionKind::kAccel;
  /// the scan's in_timestamp [ns]; 0 when the layout has none
  DeviceTime device_stamp;
  /// accel: specific force [m/s^2]; gyro: angular rate [rad/s]; in the depth camera frame
  /// (x right, y down, z forward) unless RealsenseImuConfig::align_to_depth_frame is off
  Eigen::Vector3d xyz_depth = Eigen::Vector3d::Zero();
};

struct RealsenseImuConfig {
  /// gyro LSB [deg/s]: 0.1 (librealsense default) or 0.003814697265625 (high sensitivity)
  double gyro_deg_per_lsb = 0.1;
  /// accel LSB [g]
  double accel_g_per_lsb = 0.001;
  /// apply the D435i IMU-to-depth axis flip; off leaves the sensor's own axes
  bool align_to_depth_frame = true;
};

struct RealsenseImuCounters {
  std::uint64_t samples = 0;        ///< samples decoded
  std::uint64_t partial_bytes = 0;  ///< bytes of trailing partial records (skipped)
  std::uint64_t bad_chunks = 0;     ///< chunks refused (decoder without a valid layout)
};

class RealsenseImuDecoder {
 public:
  /// `wire_format` is the Source's channel wire format ("iio-hid-accel-3d;in_accel_x:..." or the
  /// gyro's), which names the kind and carries the record layout.
  RealsenseImuDecoder(std::string_view wire_format, RealsenseImuConfig config = {});
  /// false (and every decode() returns 0, counted) when the wire format was unusable; error()
  /// says why.
  bool valid() const { return valid_; }
  const std::string& error() const { return error_; }
  MotionKind kind() const { return kind_; }
  std::uint32_t record_bytes() const { return layout_.record_bytes; }

  /// Decodes the whole records in `bytes` into `out` (at most out.size()); returns how many.
  std::size_t decode(std::span<const std::byte> bytes, std::span<D4xxMotionSample> out);
  const RealsenseImuCounters& counters() const { return counters_; }

 private:
  IioScanLayout layout_;
  const IioScanElement* axis_[3] = {nullptr, nullptr, nullptr};
  const IioScanElement* timestamp_ = nullptr;
  MotionKind kind_ = MotionKind::kAccel;
  double scale_ = 0.0;  // raw LSB -> SI
  double flip_[3] = {1.0, 1.0, 1.0};
  bool valid_ = false;
  std::string error_;
  RealsenseImuCounters counters_;
};

}  // namespace posed::drivers::camera
