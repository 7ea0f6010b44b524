#pragma once
// The inverse of drivers/imu/can_imu_mapping: turns one IMU sample (sensor axes, SI) into the CAN
// frames a device described by a CanImuMapping would send, and a frame into a candump log line,
// so tests can make CAN IMU traffic for any mapping. Frames come in the order their IDs first
// appear in the mapping, the completing frame last.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "drivers/imu/can_frame.hpp"
#include "drivers/imu/can_imu_mapping.hpp"

namespace posed::test {

inline void put_raw(drivers::can::CanFrame& frame, const drivers::can::CanFieldMap& f,
                    double value) {
  namespace can = drivers::can;
  const double raw = (value - f.offset) / f.scale;
  std::uint32_t u = 0;
  switch (f.type) {
    case can::FieldType::kU8:
    case can::FieldType::kU16:
    case can::FieldType::kU32:
      u = static_cast<std::uint32_t>(std::llround(raw));
      break;
    case can::FieldType::kI8:
    case can::FieldType::kI16:
    case can::FieldType::kI32:
      u = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::llround(raw)));
      break;
    case can::FieldType::kF32: {
      const auto fl = static_cast<float>(raw);
      std::memcpy(&u, &fl, 4);
      break;
    }
  }
  const std::size_t n = can::field_size(f.type);
  for (std::size_t i = 0; i < n; ++i) {
    const auto b = static_cast<std::uint8_t>(u >> (8 * i));  // byte i, least significant first
    frame.data[f.byte_offset + (f.big_endian ? n - 1 - i : i)] = b;
  }
  frame.len = static_cast<std::uint8_t>(std::max<std::size_t>(frame.len, f.byte_offset + n));
}

/// The frames of one sample; `counter_us` only where the mapping has a counter.
inline std::vector<drivers::can::CanFrame> encode_can_imu_sample(
    const drivers::can::CanImuMapping& mapping, const Eigen::Vector3d& gyro_radps,
    const Eigen::Vector3d& specific_force_mps2, std::uint64_t counter_us) {
  namespace can = drivers::can;
  std::vector<can::CanFrame> frames;
  const auto frame_for = [&](std::uint32_t id, bool extended) -> can::CanFrame& {
    for (auto& f : frames) {
      if (f.id == id && f.extended == extended) return f;
    }
    can::CanFrame f;
    f.id = id;
    f.extended = extended;
    frames.push_back(f);
    return frames.back();
  };
  for (const auto& f : mapping.fields) {
    const int axis = static_cast<int>(f.field) % 3;
    double v = 0;
    switch (f.field) {
      case can::ImuField::kGyroX:
      case can::ImuField::kGyroY:
      case can::ImuField::kGyroZ:
        v = gyro_radps[axis];
        break;
      case can::ImuField::kAccelX:
      case can::ImuField::kAccelY:
      case can::ImuField::kAccelZ:
        v = specific_force_mps2[axis];
        break;
      case can::ImuField::kCounter:
        v = static_cast<double>(counter_us);
        break;
    }
    put_raw(frame_for(f.can_id, f.extended), f, v);
  }
  // The completing frame goes last.
  for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
    if (frames[i].id == mapping.complete_on_id &&
        frames[i].extended == mapping.complete_on_extended) {
      std::swap(frames[i], frames.back());
      break;
    }
  }
  return frames;
}

/// A candump -l line: "(1600000000.123456) can0 181#0102..." (classic frames only).
inline std::string candump_line(std::int64_t stamp_us, const drivers::can::CanFrame& f,
                                const std::string& interface = "can0") {
  char head[64];
  std::snprintf(head, sizeof head, "(%lld.%06lld) %s ", static_cast<long long>(stamp_us / 1000000),
                static_cast<long long>(stamp_us % 1000000), interface.c_str());
  char id[16];
  std::snprintf(id, sizeof id, f.extended ? "%08X#" : "%03X#", f.id);
  std::string line = std::string(head) + id;
  for (std::size_t i = 0; i < f.len; ++i) {
    char b[4];
    std::snprintf(b, sizeof b, "%02X", f.data[i]);
    line += b;
  }
  return line + "\n";
}

}  // namespace posed::test
