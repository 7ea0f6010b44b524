#include "core/sync/clockless_stamper.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/sync/simulated_clock.hpp"

namespace posed {
// Named rather than anonymous: test binaries build as unity batches, where another file's
// helpers of the same name share the translation unit.
namespace clockless_stamper_test {

/// The PLUG 617 over UVC: 25 Hz, no clock, 12 ms minimum latency, 2 ms of one-sided jitter.
SimulatedStreamConfig thermal_camera(std::uint64_t seed) {
  SimulatedStreamConfig c;
  c.kind = DeviceClockKind::kNone;
  c.rate_hz = 25.0;
  c.drift_ppm = 60.0;
  c.latency = Duration::from_ms(12);
  c.jitter_mean = Duration::from_us(500);
  c.jitter_max = Duration::from_ms(2);
  c.drop_probability = 0.10;
  c.seed = seed;
  return c;
}

ClockSyncConfig config_for(const SimulatedStreamConfig& sim) {
  ClockSyncConfig c;
  c.kind = DeviceClockKind::kNone;
  c.nominal_rate_hz = 25.0;
  c.latency = sim.latency;
  return c;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

/// Frames missing from the simulated sequence (what the stamper should count as dropped).
std::uint64_t true_drops(const std::vector<SimulatedSample>& samples) {
  std::uint64_t drops = 0;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    drops += samples[i].sequence - samples[i - 1].sequence - 1;
  }
  return drops;
}

struct Errors {
  std::vector<double> regularised_ns;
  std::vector<double> naive_ns;
};

template <class StampFn>
Errors run(const std::vector<SimulatedSample>& samples, Duration latency, StampFn&& stamp_fn) {
  Errors e;
  const HostTime first = samples.front().true_stamp;
  for (const auto& s : samples) {
    const HostTime stamp = stamp_fn(s);
    if (s.true_stamp - first < Duration::from_s(10)) continue;
    e.regularised_ns.push_back(std::abs(static_cast<double>((stamp - s.true_stamp).ns)));
    e.naive_ns.push_back(std::abs(static_cast<double>((s.arrival - latency - s.true_stamp).ns)));
  }
  return e;
}

TEST(ClocklessStamper, RegularisesArrivalsAgainstThePeriodAndCountsDrops) {
  const auto sim = thermal_camera(31);
  const auto samples = simulate_stream(sim, Duration::from_s(40));
  ClocklessStamper stamper(config_for(sim));
  const Errors e = run(samples, sim.latency,
                       [&](const SimulatedSample& s) { return stamper.stamp(s.arrival).stamp; });
  EXPECT_LT(percentile(e.regularised_ns, 0.99), 1'000'000.0);
  // Jitter must not reach the stamps: far better than arrival - latency.
  EXPECT_LT(percentile(e.regularised_ns, 0.99), percentile(e.naive_ns, 0.99) / 4.0);
  const auto st = stamper.status();
  EXPECT_EQ(st.dropped_frames, true_drops(samples));
  EXPECT_GT(st.dropped_frames, 50u);
  EXPECT_EQ(st.state, SyncState::kLocked);
  EXPECT_NEAR(st.drift_ppm, 60.0, 10.0);
}

TEST(ClocklessStamper, LateFramesAreNotMistakenForDropsForLong) {
  auto sim = thermal_camera(32);
  sim.spike_probability = 0.01;
  sim.spike_delay = Duration::from_ms(50);  // longer than the 40 ms period
  const auto samples = simulate_stream(sim, Duration::from_s(40));
  ClocklessStamper stamper(config_for(sim));
  std::vector<double> errors;
  std::size_t off_by_a_period = 0;
  for (const auto& s : samples) {
    const HostTime stamp = stamper.stamp(s.arrival).stamp;
    const double err = std::abs(static_cast<double>((stamp - s.true_stamp).ns));
    if (s.true_stamp - samples.front().true_stamp < Duration::from_s(10)) continue;
    errors.push_back(err);
    if (err > 20'000'000.0) ++off_by_a_period;
  }
  EXPECT_GT(stamper.index_corrections(), 0u);
  // Only the late frames themselves may be a period off; those after them are right again.
  EXPECT_LE(off_by_a_period, stamper.index_corrections());
  EXPECT_LT(percentile(errors, 0.95), 1'000'000.0);
  EXPECT_EQ(stamper.status().jumps + stamper.status().resets, 0u);
}

TEST(ClocklessStamper, SequenceNumbersGiveExactDropsAndDetectRestarts) {
  auto sim = thermal_camera(33);
  sim.reset_after = Duration::from_s(20);  // the camera restarts: its sequence starts again
  const auto samples = simulate_stream(sim, Duration::from_s(40));
  ClocklessStamper stamper(config_for(sim));
  std::vector<double> errors;
  const HostTime restart_at = sim.host_start + sim.reset_after;
  std::uint64_t drops = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const auto& s = samples[i];
    const auto r = stamper.stamp(s.arrival, s.sequence);
    if (i > 0 && s.sequence > samples[i - 1].sequence) {
      drops += s.sequence - samples[i - 1].sequence - 1;
      EXPECT_EQ(r.dropped_before, s.sequence - samples[i - 1].sequence - 1);
    }
    const bool settling =
        s.true_stamp >= restart_at && s.true_stamp < restart_at + Duration::from_s(2);
    if (s.true_stamp - samples.front().true_stamp >= Duration::from_s(10) && !settling) {
      errors.push_back(std::abs(static_cast<double>((r.stamp - s.true_stamp).ns)));
    }
  }
  EXPECT_EQ(stamper.status().resets, 1u);
  EXPECT_EQ(stamper.status().dropped_frames, drops);
  EXPECT_LT(percentile(errors, 0.99), 1'000'000.0);
}

TEST(ClocklessStamper, WithoutARateStampsAreArrivalMinusLatencyAndCounted) {
  ClockSyncConfig c;
  c.kind = DeviceClockKind::kNone;
  c.nominal_rate_hz = 0.0;
  c.latency = Duration::from_ms(5);
  ClocklessStamper stamper(c);
  EXPECT_EQ(stamper.nominal_period().ns, 0);
  EXPECT_EQ(stamper.stamp(HostTime::from_ns(100'000'000)).stamp.ns, 95'000'000);
  EXPECT_EQ(stamper.stamp(HostTime::from_ns(140'000'000), 7).stamp.ns, 135'000'000);
  EXPECT_EQ(stamper.status().rejected, 2u);
}

}  // namespace clockless_stamper_test
}  // namespace posed
