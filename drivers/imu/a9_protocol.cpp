#include "drivers/imu/a9_protocol.hpp"

#include <Eigen/Dense>
#include <bit>
#include <cmath>
#include <cstring>

namespace posed::drivers::a9 {
namespace {

constexpr std::array<std::uint16_t, 256> make_crc_table() {
  std::array<std::uint16_t, 256> table{};
  for (unsigned i = 0; i < 256; ++i) {
    auto crc = static_cast<std::uint16_t>(i);
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 1u) ? static_cast<std::uint16_t>((crc >> 1) ^ 0xA001u)
                       : static_cast<std::uint16_t>(crc >> 1);
    }
    table[i] = crc;
  }
  return table;
}
// Table-driven: the bit-wise loop would cap the parser well below the 50 MB/s target.
constexpr auto kCrcTable = make_crc_table();

std::uint32_t load_u32_le(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

float load_f32_le(const std::uint8_t* p) { return std::bit_cast<float>(load_u32_le(p)); }

void store_u32_le(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
  p[2] = static_cast<std::uint8_t>(v >> 16);
  p[3] = static_cast<std::uint8_t>(v >> 24);
}

void store_f32_le(std::uint8_t* p, float v) { store_u32_le(p, std::bit_cast<std::uint32_t>(v)); }

// Body offsets (from the frame start): info at 3, counter at 7, floats from 11.
constexpr std::size_t kInfoAt = 3;
constexpr std::size_t kCounterAt = 7;
constexpr std::size_t kFloatsAt = 11;

/// Writes header, info, counter and CRC around `floats` already placed at kFloatsAt.
std::size_t finish_frame(std::uint8_t len, std::uint32_t info, std::uint32_t counter,
                         std::span<std::uint8_t> out) {
  const std::size_t total = std::size_t{len} + kFrameOverhead;
  out[0] = kSync0;
  out[1] = kSync1;
  out[2] = len;
  store_u32_le(&out[kInfoAt], info);
  store_u32_le(&out[kCounterAt], counter);
  const std::uint16_t crc = crc16_modbus(out.subspan(2, total - 4));
  out[total - 2] = static_cast<std::uint8_t>(crc);
  out[total - 1] = static_cast<std::uint8_t>(crc >> 8);
  return total;
}

Eigen::Matrix3d rotation(const A9Mounting& m) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      R(r, c) = m.R_imu_sensor[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
    }
  }
  return R;
}

Eigen::Vector3d to_vec(const std::array<float, 3>& a) {
  return {static_cast<double>(a[0]), static_cast<double>(a[1]), static_cast<double>(a[2])};
}

std::array<float, 3> to_floats(const Eigen::Vector3d& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

}  // namespace

std::uint16_t crc16_modbus(std::span<const std::uint8_t> bytes) {
  std::uint16_t crc = 0xFFFF;
  for (const std::uint8_t b : bytes) {
    crc = static_cast<std::uint16_t>((crc >> 8) ^ kCrcTable[(crc ^ b) & 0xFFu]);
  }
  return crc;
}

std::size_t encode_a9_sensor_frame(const A9SensorFrame& frame, std::span<std::uint8_t> out) {
  if (out.size() < kSensorFrameSize) return 0;
  std::uint8_t* p = &out[kFloatsAt];
  for (const auto* group : {&frame.gyro_radps, &frame.accel_g, &frame.mag}) {
    for (const float v : *group) {
      store_f32_le(p, v);
      p += 4;
    }
  }
  return finish_frame(kSensorLen, frame.frame_info, frame.counter_us, out);
}

std::size_t encode_a9_attitude_frame(const A9AttitudeFrame& frame, std::span<std::uint8_t> out) {
  if (out.size() < kAttitudeFrameSize) return 0;
  store_f32_le(&out[kFloatsAt], frame.roll_deg);
  store_f32_le(&out[kFloatsAt + 4], frame.pitch_deg);
  store_f32_le(&out[kFloatsAt + 8], frame.yaw_deg);
  return finish_frame(kAttitudeLen, frame.frame_info, frame.counter_us, out);
}

A9Decoder::Check A9Decoder::check_candidate(std::span<const std::uint8_t> bytes,
                                            std::uint64_t offset, A9Frame& frame,
                                            std::size_t& frame_size) {
  // bytes[0] is 0xAA (callers guarantee it).
  if (bytes.size() < 2) return Check::kNeedMore;
  if (bytes[1] != kSync1) return Check::kNoSync;
  if (bytes.size() < 3) return Check::kNeedMore;
  const std::uint8_t len = bytes[2];
  // Too short to hold info + counter: cannot be a frame, so it is noise, not a bad frame.
  if (len < kMinBodyLen) return Check::kNoSync;
  const std::size_t total = std::size_t{len} + kFrameOverhead;
  frame_size = total;
  if (bytes.size() < total) return Check::kNeedMore;

  const std::uint16_t computed = crc16_modbus(bytes.subspan(2, total - 4));
  const auto stored =
      static_cast<std::uint16_t>(bytes[total - 2] | (static_cast<unsigned>(bytes[total - 1]) << 8));
  if (computed != stored) {
    last_error_ = DecodeError{offset, len, stored, computed};
    // A sync pattern inside the candidate means another frame began before this one ended:
    // bytes were lost, the frame is truncated rather than corrupted.
    for (std::size_t i = 1; i + 1 < total; ++i) {
      if (bytes[i] == kSync0 && bytes[i + 1] == kSync1) return Check::kTruncated;
    }
    return Check::kBadCrc;
  }

  const std::uint8_t* p = bytes.data();
  if (len == kSensorLen) {
    frame.kind = FrameKind::kSensor;
    A9SensorFrame& s = frame.sensor;
    s.frame_info = load_u32_le(p + kInfoAt);
    s.counter_us = load_u32_le(p + kCounterAt);
    for (std::size_t i = 0; i < 3; ++i) {
      s.gyro_radps[i] = load_f32_le(p + kFloatsAt + 4 * i);
      s.accel_g[i] = load_f32_le(p + kFloatsAt + 12 + 4 * i);
      s.mag[i] = load_f32_le(p + kFloatsAt + 24 + 4 * i);
    }
  } else if (len == kAttitudeLen) {
    frame.kind = FrameKind::kAttitude;
    A9AttitudeFrame& a = frame.attitude;
    a.frame_info = load_u32_le(p + kInfoAt);
    a.counter_us = load_u32_le(p + kCounterAt);
    a.roll_deg = load_f32_le(p + kFloatsAt);
    a.pitch_deg = load_f32_le(p + kFloatsAt + 4);
    a.yaw_deg = load_f32_le(p + kFloatsAt + 8);
  } else {
    last_error_ = DecodeError{offset, len, stored, computed};
    return Check::kUnknownKind;
  }
  frame.stream_offset = offset;
  return Check::kFrame;
}

// Drops `n` bytes from the front of the partial buffer, then everything up to the next 0xAA;
// all of them counted as skipped. Returns kNeedMore for convenience.
DecodeStatus A9Decoder::drop_pending_front(std::size_t n) {
  std::size_t drop = n;
  while (drop < pending_len_ && pending_[drop] != kSync0) ++drop;
  counters_.skipped_bytes += drop;
  std::memmove(pending_.data(), pending_.data() + drop, pending_len_ - drop);
  pending_len_ -= drop;
  pending_offset_ += drop;
  return DecodeStatus::kNeedMore;
}

DecodeStatus A9Decoder::next(std::span<const std::uint8_t>& input, A9Frame& frame) {
  for (;;) {
    std::size_t frame_size = 0;
    if (pending_len_ > 0) {
      // Slow path: a candidate straddles reads. Top it up only to the size it needs, so the
      // buffer never holds more than one frame.
      std::size_t need = 3;
      if (pending_len_ >= 3) need = std::size_t{pending_[2]} + kFrameOverhead;
      if (need > pending_len_ && !input.empty()) {
        const std::size_t take = std::min(need - pending_len_, input.size());
        std::memcpy(pending_.data() + pending_len_, input.data(), take);
        pending_len_ += take;
        input = input.subspan(take);
        consumed_ += take;
      }
      const Check c =
          check_candidate({pending_.data(), pending_len_}, pending_offset_, frame, frame_size);
      switch (c) {
        case Check::kNeedMore:
          if (input.empty()) return DecodeStatus::kNeedMore;
          continue;
        case Check::kFrame:
          std::memmove(pending_.data(), pending_.data() + frame_size, pending_len_ - frame_size);
          pending_len_ -= frame_size;
          pending_offset_ += frame_size;
          ++counters_.frames_ok;
          if (frame.kind == FrameKind::kSensor) ++counters_.sensor_frames;
          if (pending_len_ > 0) drop_pending_front(0);
          return DecodeStatus::kFrame;
        case Check::kBadCrc:
          ++counters_.bad_crc;
          drop_pending_front(1);
          return DecodeStatus::kBadCrc;
        case Check::kTruncated:
          ++counters_.truncated;
          drop_pending_front(1);
          return DecodeStatus::kTruncated;
        case Check::kUnknownKind:
          ++counters_.unknown_kind;
          drop_pending_front(frame_size);
          return DecodeStatus::kUnknownKind;
        case Check::kNoSync:
          drop_pending_front(1);
          continue;
      }
    }

    // Fast path: parse straight from the caller's bytes, no copy.
    if (input.empty()) return DecodeStatus::kNeedMore;
    const void* hit = std::memchr(input.data(), kSync0, input.size());
    const std::size_t skip =
        hit == nullptr
            ? input.size()
            : static_cast<std::size_t>(static_cast<const std::uint8_t*>(hit) - input.data());
    counters_.skipped_bytes += skip;
    consumed_ += skip;
    input = input.subspan(skip);
    if (input.empty()) return DecodeStatus::kNeedMore;

    const Check c = check_candidate(input, consumed_, frame, frame_size);
    std::size_t advance = 1;
    DecodeStatus status = DecodeStatus::kNeedMore;
    switch (c) {
      case Check::kNeedMore:
        // The rest is shorter than the frame it starts (≤ kMaxFrameSize): keep it.
        std::memcpy(pending_.data(), input.data(), input.size());
        pending_len_ = input.size();
        pending_offset_ = consumed_;
        consumed_ += input.size();
        input = {};
        return DecodeStatus::kNeedMore;
      case Check::kFrame:
        ++counters_.frames_ok;
        if (frame.kind == FrameKind::kSensor) ++counters_.sensor_frames;
        consumed_ += frame_size;
        input = input.subspan(frame_size);
        return DecodeStatus::kFrame;
      case Check::kBadCrc:
        ++counters_.bad_crc;
        status = DecodeStatus::kBadCrc;
        break;
      case Check::kTruncated:
        ++counters_.truncated;
        status = DecodeStatus::kTruncated;
        break;
      case Check::kUnknownKind:
        ++counters_.unknown_kind;
        advance = frame_size;
        status = DecodeStatus::kUnknownKind;
        break;
      case Check::kNoSync:
        break;
    }
    // Rejected candidate: skip only its first byte (or the whole CRC-valid unknown frame) so a
    // good frame starting inside it is still found.
    counters_.skipped_bytes += advance;
    consumed_ += advance;
    input = input.subspan(advance);
    if (status != DecodeStatus::kNeedMore) return status;
  }
}

DecodeStatus A9Decoder::finish(A9Frame& frame) {
  // Whatever the buffer still holds complete (frames revealed by earlier rescans) comes first.
  std::span<const std::uint8_t> none;
  const DecodeStatus s = next(none, frame);
  if (s != DecodeStatus::kNeedMore || pending_len_ == 0) return s;
  last_error_ =
      DecodeError{pending_offset_, pending_len_ >= 3 ? pending_[2] : std::uint8_t{0}, 0, 0};
  ++counters_.truncated;
  drop_pending_front(1);
  return DecodeStatus::kTruncated;
}

ImuSample to_imu_sample(const A9SensorFrame& frame, const A9Mounting& mounting, HostTime stamp,
                        DeviceTime device_stamp) {
  const Eigen::Matrix3d R_imu_sensor = rotation(mounting);
  ImuSample s;
  s.stamp = stamp;
  s.device_stamp = device_stamp;
  s.angular_velocity_radps = R_imu_sensor * to_vec(frame.gyro_radps);
  s.specific_force_mps2 = R_imu_sensor * (-kGravityMps2 * to_vec(frame.accel_g));
  return s;
}

Eigen::Vector3d mag_in_imu_frame(const A9SensorFrame& frame, const A9Mounting& mounting) {
  return rotation(mounting) * to_vec(frame.mag);
}

A9SensorFrame a9_frame_from_si(const Eigen::Vector3d& gyro_radps,
                               const Eigen::Vector3d& specific_force_mps2,
                               const Eigen::Vector3d& mag, std::uint32_t counter_us,
                               const A9Mounting& mounting) {
  // R is orthonormal, so its transpose maps IMU-frame vectors back to device axes.
  const Eigen::Matrix3d R_sensor_imu = rotation(mounting).transpose();
  A9SensorFrame f;
  f.counter_us = counter_us;
  f.gyro_radps = to_floats(R_sensor_imu * gyro_radps);
  f.accel_g = to_floats(R_sensor_imu * specific_force_mps2 * (-1.0 / kGravityMps2));
  f.mag = to_floats(R_sensor_imu * mag);
  return f;
}

A9Attitude to_attitude(const A9AttitudeFrame& frame, HostTime stamp, DeviceTime device_stamp) {
  A9Attitude a;
  a.stamp = stamp;
  a.device_stamp = device_stamp;
  a.roll_rad = static_cast<double>(frame.roll_deg) * kDegToRad;
  a.pitch_rad = -static_cast<double>(frame.pitch_deg) * kDegToRad;
  a.yaw_rad = -static_cast<double>(frame.yaw_deg) * kDegToRad;
  return a;
}

}  // namespace posed::drivers::a9
