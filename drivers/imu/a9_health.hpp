#pragma once
// Stream health of an A9 from its own frames: rate measured on the device counter (immune to
// USB/host jitter), gaps and duplicates in the counter, and saturated samples. Pure; the status
// publisher copies the plain A9Health struct.

#include <cstdint>

#include "drivers/imu/a9_protocol.hpp"

namespace posed::drivers::a9 {

struct A9HealthConfig {
  /// rate the device is configured for (M2DGR: 150) [Hz]
  double nominal_rate_hz = 150.0;
  /// a counter step longer than this many nominal periods is a gap [-]
  double gap_factor = 1.5;
  /// |gyro| component at or above this is saturated; A9 range ±2000 °/s, 1 % margin [rad/s]
  double gyro_saturation_radps = 2000.0 * 0.99 * 3.14159265358979323846 / 180.0;
  /// |accel| component at or above this is saturated; A9 range ±16 g, 1 % margin [g]
  double accel_saturation_g = 16.0 * 0.99;
  /// smoothing of the measured period, weight of the newest interval [-]
  double rate_smoothing = 0.05;
};

struct A9Health {
  /// sensor frames seen
  std::uint64_t frames = 0;
  /// measured sample rate from the device counter, smoothed; 0 until two frames [Hz]
  double rate_hz = 0.0;
  /// counter steps longer than gap_factor nominal periods
  std::uint64_t gaps = 0;
  /// frames missing inside those gaps (step / nominal period − 1, rounded)
  std::uint64_t missed_frames = 0;
  /// frames repeating the previous counter
  std::uint64_t duplicate_counters = 0;
  /// frames whose counter went backwards (device reset; wraps are not counted)
  std::uint64_t backwards_counters = 0;
  /// frames with any gyro or accel component at its saturation limit
  std::uint64_t saturated = 0;
  /// longest counter step seen [µs]
  std::uint32_t max_step_us = 0;
  /// last device counter [µs]
  std::uint32_t last_counter_us = 0;
};

class A9HealthMonitor {
 public:
  explicit A9HealthMonitor(A9HealthConfig config = {}) : config_(config) {}
  void update(const A9SensorFrame& frame);
  const A9Health& health() const { return health_; }

 private:
  A9HealthConfig config_;
  A9Health health_;
  /// smoothed counter step [µs]
  double period_us_ = 0.0;
};

}  // namespace posed::drivers::a9
