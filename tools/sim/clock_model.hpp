#pragma once
// How a simulated device's clock and its transport relate to true time:
//   device time  = offset + t + drift·t          (the device's crystal runs fast or slow)
//   host arrival = host_epoch + t_sent + latency + Exp(jitter_mean)
// The delay is one-sided (a packet is never early), as ClockSync's minimum-delay model assumes,
// and arrivals on one stream never reorder (serial bytes and UDP on one link are FIFO).
// The host clock is the simulator's reference clock: host time = host_epoch + true time.

#include <cstdint>
#include <random>

#include "core/time.hpp"

namespace posed::sim {

struct ClockModelConfig {
  /// device time at true time 0 [ns]
  std::int64_t offset_ns = 0;
  /// device clock rate error (+ = device runs fast) [ppm]
  double drift_ppm = 0.0;
  /// minimum transport delay, sent to host arrival [ns]
  std::int64_t latency_ns = 0;
  /// mean of the exponential extra delay on top of the latency [ns]
  std::int64_t jitter_mean_ns = 0;
};

class ClockModel {
 public:
  ClockModel() = default;
  ClockModel(ClockModelConfig config, std::int64_t host_epoch_ns, std::uint64_t seed)
      : config_(config), host_epoch_ns_(host_epoch_ns), rng_(seed) {}

  /// The device clock at true time `t` [ns since the device's epoch].
  DeviceTime device_at(Duration t) const;
  /// The true time at which the device clock reads `d` (inverse of device_at, ±1 ns).
  Duration true_at(DeviceTime d) const;
  /// Host time of true time `t` (no transport).
  HostTime host_at(Duration t) const { return HostTime::from_ns(host_epoch_ns_ + t.ns); }
  /// Host arrival of data sent at true time `t_sent`: latency plus exponential jitter, never
  /// before the previous arrival on this stream (+1 ns). Advances the stream's RNG.
  HostTime arrival(Duration t_sent);

  const ClockModelConfig& config() const { return config_; }

 private:
  ClockModelConfig config_;
  std::int64_t host_epoch_ns_ = 0;
  std::mt19937_64 rng_;
  std::int64_t last_arrival_ns_ = INT64_MIN;
};

/// The regular events of a free-running device (IMU samples, camera exposure midpoints), timed
/// by its own clock: event k (k = 0, 1, ...) at device time start + phase + (k + 1)·period, with
/// start the device clock at true time 0. Spaced on the device clock, so the host sees the
/// device's drift in their arrivals.
class DeviceSchedule {
 public:
  DeviceSchedule() = default;
  /// `rate_hz` on the device's clock; `phase` shifts every event (a stream started later).
  DeviceSchedule(const ClockModel& clock, double rate_hz, Duration phase = Duration::from_ns(0));

  /// Device time of event k.
  DeviceTime device(std::uint64_t k) const;
  /// True time of event k.
  Duration true_time(std::uint64_t k) const { return clock_.true_at(device(k)); }
  /// the nominal period [s]
  double period_s() const { return period_ns_ * 1e-9; }
  double rate_hz() const { return 1e9 / period_ns_; }

 private:
  ClockModel clock_;
  DeviceTime start_;
  double period_ns_ = 1e9;
};

}  // namespace posed::sim
