#pragma once
// A deterministic model of a sensor stream's clock and transport, for unit tests, `posectl bench
// sync` and simulation: a device clock with drift that samples at its own nominal period, a
// one-sided transport delay (fixed latency + exponential jitter + rare spikes), dropped samples,
// an optional device reset, and arrivals sorted by host time (so stamps arrive out of order
// when delays overtake the period). Seeded; no clock is read.

#include <cstdint>
#include <vector>

#include "core/sync/clock_sync_types.hpp"
#include "core/time.hpp"

namespace posed {

struct SimulatedStreamConfig {
  /// how the simulated device encodes its stamps in SimulatedSample::raw
  DeviceClockKind kind = DeviceClockKind::kHardwareNs;
  /// sample rate in device time [Hz]
  double rate_hz = 200.0;
  /// device clock rate error: host elapsed = device elapsed * (1 + drift) [ppm]
  double drift_ppm = 0.0;
  /// device stamp of the first sample [ns]
  DeviceTime device_start;
  /// true host time of the first sample [ns]
  HostTime host_start = HostTime::from_ns(1'000'000'000);
  /// fixed minimum transport latency [ns]
  Duration latency = Duration::from_ms(1);
  /// mean of the exponential one-sided jitter added to the latency [ns]
  Duration jitter_mean = Duration::from_ms(1);
  /// the exponential jitter is capped here [ns]
  Duration jitter_max = Duration::from_ms(5);
  /// probability that a sample gets `spike_delay` on top of its jitter [1]
  double spike_probability = 0.0;
  /// extra delay of a spike [ns]
  Duration spike_delay = Duration::from_ms(50);
  /// probability that a sample is lost in transport [1]
  double drop_probability = 0.0;
  /// host time after host_start at which the device resets; <= 0 for no reset [ns]
  Duration reset_after = Duration::from_ns(0);
  /// device stamp right after the reset [ns]
  DeviceTime device_after_reset;
  /// random seed (SplitMix64, portable across standard libraries)
  std::uint64_t seed = 1;
};

struct SimulatedSample {
  /// when the device really sampled, on the host clock (the truth a stamp is judged against)
  HostTime true_stamp;
  /// host arrival time
  HostTime arrival;
  /// the device's own stamp, unwrapped [ns]
  DeviceTime device_stamp;
  /// the stamp as the device sends it: µs counter mod 2^32, µs past the hour, ns, or 0
  std::uint64_t raw = 0;
  /// per-device sample counter, restarting at 0 on a reset (like a V4L2 frame sequence)
  std::uint64_t sequence = 0;
  /// sampled after the device reset
  bool after_reset = false;
};

/// Simulates `length` of host time; samples in arrival order (dropped ones absent).
std::vector<SimulatedSample> simulate_stream(const SimulatedStreamConfig& config, Duration length);

/// The transport the time-sync issue specifies for clocked devices, shared by the tests and
/// `posectl bench sync`: 0-5 ms one-sided exponential jitter (mean 1 ms), 0.5 % spikes of 50 ms,
/// 10 % of samples lost, on top of a fixed `latency`.
SimulatedStreamConfig harsh_transport(DeviceClockKind kind, double rate_hz, double drift_ppm,
                                      Duration latency, std::uint64_t seed);

}  // namespace posed
