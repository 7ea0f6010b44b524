#include "tools/sim/clock_model.hpp"

#include <cmath>

namespace posed::sim {

DeviceTime ClockModel::device_at(Duration t) const {
  const double drift_ns = static_cast<double>(t.ns) * config_.drift_ppm * 1e-6;
  return DeviceTime::from_ns(config_.offset_ns + t.ns + std::llround(drift_ns));
}

Duration ClockModel::true_at(DeviceTime d) const {
  const double since = static_cast<double>(d.ns - config_.offset_ns);
  return Duration::from_ns(std::llround(since / (1.0 + config_.drift_ppm * 1e-6)));
}

HostTime ClockModel::arrival(Duration t_sent) {
  std::int64_t jitter = 0;
  if (config_.jitter_mean_ns > 0) {
    std::exponential_distribution<double> exp(1.0 / static_cast<double>(config_.jitter_mean_ns));
    jitter = std::llround(exp(rng_));
  }
  std::int64_t t = host_epoch_ns_ + t_sent.ns + config_.latency_ns + jitter;
  if (last_arrival_ns_ != INT64_MIN && t <= last_arrival_ns_) t = last_arrival_ns_ + 1;
  last_arrival_ns_ = t;
  return HostTime::from_ns(t);
}

DeviceSchedule::DeviceSchedule(const ClockModel& clock, double rate_hz, Duration phase)
    : clock_(clock),
      start_(clock.device_at(Duration::from_ns(0)) + phase),
      period_ns_(1e9 / rate_hz) {}

DeviceTime DeviceSchedule::device(std::uint64_t k) const {
  return start_ + Duration::from_ns(std::llround(static_cast<double>(k + 1) * period_ns_));
}

}  // namespace posed::sim
