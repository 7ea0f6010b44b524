#include "core/sync/simulated_clock.hpp"

#include <algorithm>
#include <cmath>

namespace posed {
namespace {

/// SplitMix64: tiny, fast and identical on every platform (std distributions are not).
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// uniform in [0, 1)
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

std::uint64_t raw_of(DeviceClockKind kind, DeviceTime d) {
  const auto us = static_cast<std::uint64_t>(d.ns / 1000);
  switch (kind) {
    case DeviceClockKind::kCounterUs32Bit:
      return us & 0xFFFF'FFFFull;
    case DeviceClockKind::kUsPastHour:
      return us % 3'600'000'000ull;
    case DeviceClockKind::kHardwareNs:
      return static_cast<std::uint64_t>(d.ns);
    case DeviceClockKind::kNone:
      break;
  }
  return 0;
}

}  // namespace

std::vector<SimulatedSample> simulate_stream(const SimulatedStreamConfig& c, Duration length) {
  std::vector<SimulatedSample> out;
  if (c.rate_hz <= 0.0 || length.ns <= 0) return out;
  SplitMix64 rng(c.seed);
  const double period_ns = 1e9 / c.rate_hz;
  const double host_per_device = 1.0 + c.drift_ppm * 1e-6;
  out.reserve(static_cast<std::size_t>(length.seconds() * c.rate_hz) + 1);

  bool after_reset = false;
  DeviceTime epoch_device = c.device_start;
  HostTime epoch_host = c.host_start;
  const HostTime end = c.host_start + length;
  const bool will_reset = c.reset_after.ns > 0;
  const HostTime reset_at = c.host_start + c.reset_after;
  auto at = [&](std::uint64_t k) {
    return static_cast<std::int64_t>(std::llround(static_cast<double>(k) * period_ns));
  };
  for (std::uint64_t k = 0;; ++k) {
    HostTime truth =
        epoch_host + Duration::from_ns(std::llround(static_cast<double>(at(k)) * host_per_device));
    if (will_reset && !after_reset && truth >= reset_at) {
      // The device restarts here: its clock begins again from device_after_reset and its
      // sample counter from 0; this sample is the first of the new epoch.
      after_reset = true;
      epoch_device = c.device_after_reset;
      epoch_host = truth;
      k = 0;
    }
    if (truth >= end) break;
    const DeviceTime device = epoch_device + Duration::from_ns(at(k));
    // Always draw the same number of variates per sample so drop/spike choices do not shift
    // the jitter sequence: runs with and without drops stay comparable.
    const double u_drop = rng.uniform();
    const double u_spike = rng.uniform();
    const double u_jitter = rng.uniform();
    if (u_drop < c.drop_probability) continue;
    double jitter = -static_cast<double>(c.jitter_mean.ns) * std::log1p(-u_jitter);
    jitter = std::min(jitter, static_cast<double>(c.jitter_max.ns));
    Duration delay = c.latency + Duration::from_ns(std::llround(jitter));
    if (u_spike < c.spike_probability) delay += c.spike_delay;
    SimulatedSample s;
    s.true_stamp = truth;
    s.arrival = truth + delay;
    s.device_stamp = device;
    s.raw = raw_of(c.kind, device);
    s.sequence = k;
    s.after_reset = after_reset;
    out.push_back(s);
  }
  std::stable_sort(out.begin(), out.end(), [](const SimulatedSample& a, const SimulatedSample& b) {
    return a.arrival < b.arrival;
  });
  return out;
}

SimulatedStreamConfig harsh_transport(DeviceClockKind kind, double rate_hz, double drift_ppm,
                                      Duration latency, std::uint64_t seed) {
  SimulatedStreamConfig c;
  c.kind = kind;
  c.rate_hz = rate_hz;
  c.drift_ppm = drift_ppm;
  c.latency = latency;
  c.jitter_mean = Duration::from_ms(1);
  c.jitter_max = Duration::from_ms(5);
  c.spike_probability = 0.005;
  c.spike_delay = Duration::from_ms(50);
  c.drop_probability = 0.10;
  c.seed = seed;
  return c;
}

}  // namespace posed
