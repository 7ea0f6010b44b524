#pragma once
// IMUs that output over CAN, described by data instead of code: which frame ID carries which
// field, at which byte, in which type and byte order, with which scale to SI. Pure decoder.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/measurements.hpp"
#include "drivers/imu/a9_protocol.hpp"
#include "drivers/imu/can_frame.hpp"

namespace posed::drivers::can {

enum class ImuField : std::uint8_t { kGyroX, kGyroY, kGyroZ, kAccelX, kAccelY, kAccelZ, kCounter };
enum class FieldType : std::uint8_t { kU8, kI8, kU16, kI16, kU32, kI32, kF32 };

/// The names configuration files use: gyro_x .. accel_z, counter; u8 .. i32, f32.
std::string_view to_string(ImuField field);
std::string_view to_string(FieldType type);
std::optional<ImuField> imu_field_from_string(std::string_view name);
std::optional<FieldType> field_type_from_string(std::string_view name);
/// Size of a field of `type` [B].
std::size_t field_size(FieldType type);

/// One field: value = raw · scale + offset.
struct CanFieldMap {
  /// frame ID carrying the field (without flag bits)
  std::uint32_t can_id = 0;
  /// whether `can_id` is a 29-bit ID
  bool extended = false;
  ImuField field = ImuField::kGyroX;
  /// first byte of the field in the frame's data [B]
  std::uint8_t byte_offset = 0;
  FieldType type = FieldType::kI16;
  /// Motorola (big-endian) byte order; Intel (little-endian) otherwise
  bool big_endian = false;
  /// raw → SI: gyro to [rad/s], accel to specific force [m/s^2] (a negative scale flips a device
  /// that reports minus specific force), counter to [µs]
  double scale = 1.0;
  /// added after scaling, same unit as the result
  double offset = 0.0;
};

struct CanImuMapping {
  std::vector<CanFieldMap> fields;
  /// the frame that completes a sample (usually the last one the IMU sends per sample)
  std::uint32_t complete_on_id = 0;
  bool complete_on_extended = false;
};

/// Checks a mapping: each of the six gyro/accel fields exactly once, fields inside 64 bytes,
/// completing ID among the mapped IDs. On failure says which field and why.
bool validate(const CanImuMapping& mapping, std::string& error);
/// The same; on failure `bad_field` is the index of the offending entry of `mapping.fields`, or
/// npos when the problem is the mapping as a whole (an axis missing, the completing ID), so a
/// config loader can point at the line.
bool validate(const CanImuMapping& mapping, std::string& error, std::size_t& bad_field);

/// One sample in the sensor's axes, SI.
struct CanImuReading {
  /// [rad/s]
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
  /// specific force [m/s^2]
  Eigen::Vector3d specific_force_mps2 = Eigen::Vector3d::Zero();
  /// device counter if mapped [µs]
  std::uint64_t counter_us = 0;
  bool has_counter = false;
};

enum class CanImuStatus : std::uint8_t {
  kIgnored,     ///< frame ID not in the mapping (or an error/remote frame)
  kPartial,     ///< fields stored, sample not complete yet
  kSample,      ///< `reading` holds a complete sample
  kTooShort,    ///< a mapped field lies beyond the frame's data length; frame dropped
  kIncomplete,  ///< the completing frame came but some fields were missing; sample dropped
};

struct CanImuCounters {
  std::uint64_t samples = 0;
  std::uint64_t ignored = 0;
  std::uint64_t too_short = 0;
  std::uint64_t incomplete = 0;
};

class CanImuDecoder {
 public:
  /// `mapping` must pass validate(); an invalid one decodes nothing (every frame kIgnored).
  explicit CanImuDecoder(CanImuMapping mapping);
  CanImuStatus decode(const CanFrame& frame, CanImuReading& reading);
  const CanImuCounters& counters() const { return counters_; }

 private:
  CanImuMapping mapping_;
  bool valid_ = false;
  CanImuReading pending_;
  /// bit i set when ImuField i was received since the last sample
  std::uint32_t seen_ = 0;
  std::uint32_t required_ = 0;
  CanImuCounters counters_;
};

/// Sensor-axes reading → ImuSample in the IMU frame, with the same mounting struct as the A9.
ImuSample to_imu_sample(const CanImuReading& reading, const a9::A9Mounting& mounting,
                        HostTime stamp, DeviceTime device_stamp);

}  // namespace posed::drivers::can
