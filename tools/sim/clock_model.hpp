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

}  // namespace posed::sim
