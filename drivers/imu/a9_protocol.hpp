#pragma once
// Handsfree A9 serial protocol: frame layout, CRC, encoders, a streaming resynchronising decoder,
// and the conversion between raw device values and posed's SI ImuSample.
//
// Frame (checked on two real frames, /work/shared/realdata/imu_a9/):
//   AA 55 LEN | LEN body bytes | CRC-16/MODBUS over [LEN .. end of body], little-endian
//   body: u32 frame info (LE, meaning undocumented; kept raw), u32 µs counter (LE), float32 LE...
//   LEN 0x2C: gyro xyz [rad/s], accel xyz [g], mag xyz [device units]
//   LEN 0x14: roll, pitch, yaw [deg]
// A frame is LEN + 5 bytes. Everything here is pure (no I/O, no allocation).

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "core/measurements.hpp"
#include "core/time.hpp"

namespace posed::drivers::a9 {

inline constexpr std::uint8_t kSync0 = 0xAA;
inline constexpr std::uint8_t kSync1 = 0x55;
/// LEN of a sensor (gyro/accel/mag) frame
inline constexpr std::uint8_t kSensorLen = 0x2C;
/// LEN of an attitude (roll/pitch/yaw) frame
inline constexpr std::uint8_t kAttitudeLen = 0x14;
/// sync (2) + LEN (1) + CRC (2)
inline constexpr std::size_t kFrameOverhead = 5;
/// smallest body that holds frame info and counter [B]
inline constexpr std::size_t kMinBodyLen = 8;
inline constexpr std::size_t kSensorFrameSize = kSensorLen + kFrameOverhead;      // 49
inline constexpr std::size_t kAttitudeFrameSize = kAttitudeLen + kFrameOverhead;  // 25
inline constexpr std::size_t kMaxFrameSize = 255 + kFrameOverhead;
/// Standard gravity used to turn the device's [g] into [m/s^2] (M2DGR's driver used 9.8; the
/// 0.07 % difference is below the A9's scale-factor error).
inline constexpr double kGravityMps2 = 9.80665;

/// CRC-16/MODBUS (poly 0x8005 reflected, init 0xFFFF, no final xor).
std::uint16_t crc16_modbus(std::span<const std::uint8_t> bytes);

/// A sensor frame as the device sends it: device axes, device units, device sign conventions.
struct A9SensorFrame {
  /// device µs counter (wraps every 2^32 µs ≈ 71.6 min) [µs]
  std::uint32_t counter_us = 0;
  /// angular rate, device axes [rad/s]
  std::array<float, 3> gyro_radps{};
  /// accelerometer, device axes, device sign (≈ −1 g on z at rest, level: minus specific force) [g]
  std::array<float, 3> accel_g{};
  /// magnetometer, device axes, device units as sent (not converted; ≈ 0.8 magnitude indoors,
  /// the vendor driver passes the values through unscaled) [device units]
  std::array<float, 3> mag{};
  /// body bytes 0..3 as a LE u32; meaning undocumented, kept for recording/inspection
  std::uint32_t frame_info = 0;
};

/// An attitude frame as the device sends it.
struct A9AttitudeFrame {
  /// device µs counter [µs]
  std::uint32_t counter_us = 0;
  /// device Euler angles, device sign conventions [deg]
  float roll_deg = 0.f, pitch_deg = 0.f, yaw_deg = 0.f;
  /// body bytes 0..3 as a LE u32, kept raw
  std::uint32_t frame_info = 0;
};

/// Encodes a sensor frame into `out`; returns bytes written (49), or 0 when `out` is too small.
std::size_t encode_a9_sensor_frame(const A9SensorFrame& frame, std::span<std::uint8_t> out);
/// Encodes an attitude frame into `out`; returns bytes written (25), or 0 when `out` is too small.
std::size_t encode_a9_attitude_frame(const A9AttitudeFrame& frame, std::span<std::uint8_t> out);

enum class FrameKind : std::uint8_t { kSensor, kAttitude };

constexpr std::string_view to_string(FrameKind k) {
  return k == FrameKind::kSensor ? "sensor" : "attitude";
}

/// One decoded frame; `kind` says which member is valid.
struct A9Frame {
  FrameKind kind = FrameKind::kSensor;
  A9SensorFrame sensor;
  A9AttitudeFrame attitude;
  /// offset of the frame's first byte (0xAA) in the byte stream fed so far [B]
  std::uint64_t stream_offset = 0;
};

enum class DecodeStatus : std::uint8_t {
  kFrame,        ///< `frame` holds a CRC-checked frame
  kNeedMore,     ///< the input is used up; feed more bytes
  kBadCrc,       ///< a complete candidate frame failed its CRC (see last_error()); skipped
  kTruncated,    ///< a candidate was cut short by the start of another frame; skipped
  kUnknownKind,  ///< a CRC-valid frame with a LEN this decoder does not know; skipped
};

constexpr std::string_view to_string(DecodeStatus s) {
  switch (s) {
    case DecodeStatus::kFrame:
      return "frame";
    case DecodeStatus::kNeedMore:
      return "need_more";
    case DecodeStatus::kBadCrc:
      return "bad_crc";
    case DecodeStatus::kTruncated:
      return "truncated";
    case DecodeStatus::kUnknownKind:
      return "unknown_kind";
  }
  return "unknown";
}

struct DecoderCounters {
  std::uint64_t frames_ok = 0;      ///< CRC-valid sensor + attitude frames
  std::uint64_t sensor_frames = 0;  ///< of which sensor frames
  std::uint64_t bad_crc = 0;        ///< complete candidates whose CRC did not match
  std::uint64_t truncated = 0;      ///< candidates cut short (another frame started inside)
  std::uint64_t unknown_kind = 0;   ///< CRC-valid frames with an unknown LEN
  std::uint64_t skipped_bytes = 0;  ///< bytes not part of any delivered frame [B]
};

/// Context of the last rejected candidate, for log lines and `posectl inspect`.
struct DecodeError {
  /// offset of the rejected candidate's 0xAA in the stream [B]
  std::uint64_t stream_offset = 0;
  std::uint8_t len = 0;
  std::uint16_t crc_stored = 0;
  std::uint16_t crc_computed = 0;
};

/// Streaming decoder. Bytes may arrive split anywhere; garbage, CRC failures and truncated frames
/// are counted and skipped, and the bytes of a rejected candidate are re-scanned so a good frame
/// starting inside it is not lost. Holds at most one partial frame (260 B); never allocates.
/// Cost of that guarantee: a corrupted LEN (or garbage looking like a header) holds back the
/// frames behind it until LEN+5 bytes have arrived (at most 260 B, ~5 frames at 150 Hz).
class A9Decoder {
 public:
  /// Consumes bytes from the front of `input` (advancing it) until one event happens; returns
  /// it. Call again until kNeedMore. Only kFrame fills `frame`.
  DecodeStatus next(std::span<const std::uint8_t>& input, A9Frame& frame);

  /// Feeds a whole chunk, calling `on_frame(const A9Frame&)` for every good frame.
  template <class OnFrame>
  void feed(std::span<const std::uint8_t> input, OnFrame&& on_frame) {
    A9Frame frame;
    for (;;) {
      const DecodeStatus s = next(input, frame);
      if (s == DecodeStatus::kNeedMore) return;
      if (s == DecodeStatus::kFrame) on_frame(static_cast<const A9Frame&>(frame));
    }
  }

  /// End of stream: the pending partial candidate can no longer complete, so it is counted as
  /// truncated and the bytes after its first one are re-scanned (a false header with a large
  /// LEN may hide whole frames). Call until kNeedMore, like next().
  DecodeStatus finish(A9Frame& frame);

  /// finish() for callback users.
  template <class OnFrame>
  void finish(OnFrame&& on_frame) {
    A9Frame frame;
    for (DecodeStatus s; (s = finish(frame)) != DecodeStatus::kNeedMore;) {
      if (s == DecodeStatus::kFrame) on_frame(static_cast<const A9Frame&>(frame));
    }
  }

  const DecoderCounters& counters() const { return counters_; }
  const DecodeError& last_error() const { return last_error_; }
  /// bytes held in the partial-frame buffer [B]
  std::size_t pending_bytes() const { return pending_len_; }
  /// total bytes consumed from the inputs [B]
  std::uint64_t stream_position() const { return consumed_; }

 private:
  enum class Check : std::uint8_t { kNeedMore, kFrame, kBadCrc, kTruncated, kUnknownKind, kNoSync };
  Check check_candidate(std::span<const std::uint8_t> bytes, std::uint64_t offset, A9Frame& frame,
                        std::size_t& frame_size);
  DecodeStatus drop_pending_front(std::size_t n);

  std::array<std::uint8_t, kMaxFrameSize> pending_{};
  std::size_t pending_len_ = 0;
  /// stream offset of pending_[0]
  std::uint64_t pending_offset_ = 0;
  /// stream offset of the next input byte
  std::uint64_t consumed_ = 0;
  DecoderCounters counters_;
  DecodeError last_error_;
};

/// How the A9 is mounted: v_imu = R_imu_sensor · v_sensor, where "sensor" is the device's own
/// axes (after the accel sign fix) and "imu" is posed's IMU frame (x forward, y left, z up).
struct A9Mounting {
  /// rotation from device axes to IMU frame, row-major, orthonormal [-]
  std::array<std::array<double, 3>, 3> R_imu_sensor{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
};

/// Raw device frame → ImuSample in the IMU frame:
///   angular_velocity = R · gyro;   specific_force = R · (−g0 · accel_g)
/// The device reports minus specific force (−1 g on z at rest, level), so the sign is flipped
/// here, giving +9.81 m/s^2 on z at rest (ImuSample convention).
ImuSample to_imu_sample(const A9SensorFrame& frame, const A9Mounting& mounting, HostTime stamp,
                        DeviceTime device_stamp);

/// Magnetic field in the IMU frame (R · mag), device units (see A9SensorFrame::mag).
Eigen::Vector3d mag_in_imu_frame(const A9SensorFrame& frame, const A9Mounting& mounting);

/// Inverse of to_imu_sample for simulators: SI values in the IMU frame → the raw frame the device
/// would send (R^T applied, accel sign and [g] restored). Values are rounded to float32.
A9SensorFrame a9_frame_from_si(const Eigen::Vector3d& gyro_radps,
                               const Eigen::Vector3d& specific_force_mps2,
                               const Eigen::Vector3d& mag, std::uint32_t counter_us,
                               const A9Mounting& mounting = {});

/// Optional attitude measurement from the device's own filter, REP-103 Euler angles (ZYX).
struct A9Attitude {
  /// host stamp (ClockSync-mapped by the caller)
  HostTime stamp;
  /// device stamp, unwrapped
  DeviceTime device_stamp;
  /// roll about x [rad]
  double roll_rad = 0;
  /// pitch about y, REP-103 sign (device pitch negated, as M2DGR's driver did) [rad]
  double pitch_rad = 0;
  /// yaw about z, REP-103 sign (device yaw negated, as M2DGR's driver did) [rad]
  double yaw_rad = 0;
};

/// Device attitude frame → A9Attitude. Sign convention follows M2DGR's published driver
/// (quaternion from roll, −pitch, −yaw); not checked against a moving device.
A9Attitude to_attitude(const A9AttitudeFrame& frame, HostTime stamp, DeviceTime device_stamp);

}  // namespace posed::drivers::a9
