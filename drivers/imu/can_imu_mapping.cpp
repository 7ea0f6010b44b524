#include "drivers/imu/can_imu_mapping.hpp"

#include <bit>
#include <cstdio>
#include <iterator>
#include <limits>
#include <utility>

namespace posed::drivers::can {
namespace {

constexpr std::string_view kFieldNames[] = {"gyro_x",  "gyro_y",  "gyro_z", "accel_x",
                                            "accel_y", "accel_z", "counter"};
constexpr std::string_view kTypeNames[] = {"u8", "i8", "u16", "i16", "u32", "i32", "f32"};

std::size_t type_size(FieldType t) { return field_size(t); }

double read_raw(const std::uint8_t* p, FieldType t, bool big_endian) {
  const std::size_t n = type_size(t);
  std::uint32_t u = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t b = p[big_endian ? i : n - 1 - i];
    u = (u << 8) | b;
  }
  switch (t) {
    case FieldType::kU8:
    case FieldType::kU16:
    case FieldType::kU32:
      return static_cast<double>(u);
    case FieldType::kI8:
      return static_cast<double>(static_cast<std::int8_t>(u));
    case FieldType::kI16:
      return static_cast<double>(static_cast<std::int16_t>(u));
    case FieldType::kI32:
      return static_cast<double>(static_cast<std::int32_t>(u));
    case FieldType::kF32:
      return static_cast<double>(std::bit_cast<float>(u));
  }
  return 0.0;
}

constexpr std::uint32_t bit(ImuField f) { return 1u << static_cast<unsigned>(f); }
constexpr std::uint32_t kSixAxes = 0x3Fu;

}  // namespace

std::string_view to_string(ImuField field) {
  const auto i = static_cast<std::size_t>(field);
  return i < std::size(kFieldNames) ? kFieldNames[i] : std::string_view("?");
}

std::string_view to_string(FieldType type) {
  const auto i = static_cast<std::size_t>(type);
  return i < std::size(kTypeNames) ? kTypeNames[i] : std::string_view("?");
}

std::optional<ImuField> imu_field_from_string(std::string_view name) {
  for (std::size_t i = 0; i < std::size(kFieldNames); ++i) {
    if (kFieldNames[i] == name) return static_cast<ImuField>(i);
  }
  return std::nullopt;
}

std::optional<FieldType> field_type_from_string(std::string_view name) {
  for (std::size_t i = 0; i < std::size(kTypeNames); ++i) {
    if (kTypeNames[i] == name) return static_cast<FieldType>(i);
  }
  return std::nullopt;
}

std::size_t field_size(FieldType type) {
  switch (type) {
    case FieldType::kU8:
    case FieldType::kI8:
      return 1;
    case FieldType::kU16:
    case FieldType::kI16:
      return 2;
    case FieldType::kU32:
    case FieldType::kI32:
    case FieldType::kF32:
      return 4;
  }
  return 0;
}

bool validate(const CanImuMapping& mapping, std::string& error) {
  std::size_t bad_field = 0;
  return validate(mapping, error, bad_field);
}

bool validate(const CanImuMapping& mapping, std::string& error, std::size_t& bad_field) {
  bad_field = std::string::npos;
  std::uint32_t seen = 0;
  bool completes = false;
  for (std::size_t i = 0; i < mapping.fields.size(); ++i) {
    bad_field = i;
    const CanFieldMap& f = mapping.fields[i];
    const std::string where = "CAN IMU mapping field " + std::to_string(i) + " (ID 0x";
    char id[16];
    std::snprintf(id, sizeof id, "%X)", f.can_id);
    if (f.byte_offset + type_size(f.type) > 64) {
      error = where + id + ": bytes " + std::to_string(f.byte_offset) + ".." +
              std::to_string(f.byte_offset + type_size(f.type) - 1) + " exceed 64";
      return false;
    }
    if ((seen & bit(f.field)) != 0) {
      error = where + id + ": field " + std::string(to_string(f.field)) + " mapped twice";
      return false;
    }
    seen |= bit(f.field);
    completes = completes ||
                (f.can_id == mapping.complete_on_id && f.extended == mapping.complete_on_extended);
  }
  bad_field = std::string::npos;
  if ((seen & kSixAxes) != kSixAxes) {
    std::string missing;
    for (std::size_t f = 0; f < 6; ++f) {
      if ((seen & (1u << f)) == 0)
        missing += (missing.empty() ? "" : ", ") + std::string(kFieldNames[f]);
    }
    error =
        "CAN IMU mapping: gyro x/y/z and accel x/y/z must all be mapped (missing: " + missing + ")";
    return false;
  }
  if (!completes) {
    error = "CAN IMU mapping: complete_on_id is not one of the mapped IDs";
    return false;
  }
  return true;
}

CanImuDecoder::CanImuDecoder(CanImuMapping mapping) : mapping_(std::move(mapping)) {
  std::string error;
  valid_ = validate(mapping_, error);
  for (const auto& f : mapping_.fields) required_ |= bit(f.field);
}

CanImuStatus CanImuDecoder::decode(const CanFrame& frame, CanImuReading& reading) {
  if (!valid_ || frame.error || frame.remote) {
    ++counters_.ignored;
    return CanImuStatus::kIgnored;
  }
  bool mapped = false;
  // Check lengths first so a short frame leaves no half-updated sample behind.
  for (const auto& f : mapping_.fields) {
    if (f.can_id != frame.id || f.extended != frame.extended) continue;
    mapped = true;
    if (f.byte_offset + type_size(f.type) > frame.len) {
      ++counters_.too_short;
      return CanImuStatus::kTooShort;
    }
  }
  if (!mapped) {
    ++counters_.ignored;
    return CanImuStatus::kIgnored;
  }
  for (const auto& f : mapping_.fields) {
    if (f.can_id != frame.id || f.extended != frame.extended) continue;
    const double v =
        read_raw(&frame.data[f.byte_offset], f.type, f.big_endian) * f.scale + f.offset;
    const auto axis = static_cast<int>(f.field) % 3;
    switch (f.field) {
      case ImuField::kGyroX:
      case ImuField::kGyroY:
      case ImuField::kGyroZ:
        pending_.gyro_radps[axis] = v;
        break;
      case ImuField::kAccelX:
      case ImuField::kAccelY:
      case ImuField::kAccelZ:
        pending_.specific_force_mps2[axis] = v;
        break;
      case ImuField::kCounter:
        // Clamped to [0, 2^64) first: an f32 NaN/inf or a large scale would make the cast UB.
        pending_.counter_us = !(v > 0)      ? 0
                              : v >= 0x1p64 ? std::numeric_limits<std::uint64_t>::max()
                                            : static_cast<std::uint64_t>(v);
        pending_.has_counter = true;
        break;
    }
    seen_ |= bit(f.field);
  }
  if (frame.id != mapping_.complete_on_id || frame.extended != mapping_.complete_on_extended) {
    return CanImuStatus::kPartial;
  }
  const bool complete = (seen_ & required_) == required_;
  seen_ = 0;
  if (!complete) {
    ++counters_.incomplete;
    return CanImuStatus::kIncomplete;
  }
  reading = pending_;
  ++counters_.samples;
  return CanImuStatus::kSample;
}

ImuSample to_imu_sample(const CanImuReading& reading, const a9::A9Mounting& mounting,
                        HostTime stamp, DeviceTime device_stamp) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      R(r, c) = mounting.R_imu_sensor[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
    }
  }
  ImuSample s;
  s.stamp = stamp;
  s.device_stamp = device_stamp;
  s.angular_velocity_radps = R * reading.gyro_radps;
  s.specific_force_mps2 = R * reading.specific_force_mps2;
  return s;
}

}  // namespace posed::drivers::can
