#include "core/sync/clock_sync.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

#include "core/sync/simulated_clock.hpp"

namespace posed {
namespace {

/// The transport model (core/sync/simulated_clock.hpp) with 800 µs of fixed latency.
SimulatedStreamConfig harsh_stream(DeviceClockKind kind, double rate_hz, double drift_ppm,
                                   std::uint64_t seed) {
  return harsh_transport(kind, rate_hz, drift_ppm, Duration::from_us(800), seed);
}

ClockSyncConfig config_for(const SimulatedStreamConfig& sim) {
  ClockSyncConfig c;
  c.kind = sim.kind;
  c.nominal_rate_hz = sim.rate_hz;
  c.latency = sim.latency;
  return c;
}

struct FeedResult {
  std::vector<double> abs_errors_ns;  ///< |stamp - truth| of samples in the judged interval
  std::vector<ClockEvent> events;     ///< every event, in order
};

/// Feeds the samples through `sync` (raw stamps when `raw`), judging samples whose true time
/// is at least `judge_after` past the first sample and not `skip_from`..`skip_to`.
FeedResult feed(ClockSync& sync, const std::vector<SimulatedSample>& samples, bool raw,
                Duration judge_after, HostTime skip_from = HostTime::from_ns(0),
                HostTime skip_to = HostTime::from_ns(0)) {
  FeedResult run;
  const HostTime first = samples.front().true_stamp;
  for (const auto& s : samples) {
    const HostTime stamp =
        raw ? sync.map_raw(s.raw, s.arrival) : sync.map(s.device_stamp, s.arrival);
    if (sync.last_event() != ClockEvent::kNone) run.events.push_back(sync.last_event());
    const bool skipped = s.true_stamp >= skip_from && s.true_stamp < skip_to;
    if (s.true_stamp - first >= judge_after && !skipped) {
      run.abs_errors_ns.push_back(std::abs(static_cast<double>((stamp - s.true_stamp).ns)));
    }
  }
  return run;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1));
  return v[i];
}

std::size_t count(const std::vector<ClockEvent>& events, ClockEvent e) {
  return static_cast<std::size_t>(std::count(events.begin(), events.end(), e));
}

TEST(ClockSync, ConvergesOnFastDriftingImuDespiteJitterSpikesAndDrops) {
  for (double drift_ppm : {100.0, -100.0, 0.0}) {
    const auto sim = harsh_stream(DeviceClockKind::kHardwareNs, 200.0, drift_ppm, 7);
    const auto samples = simulate_stream(sim, Duration::from_s(30));
    ClockSync sync(config_for(sim));
    const FeedResult run = feed(sync, samples, false, Duration::from_s(10));
    const ClockSyncStatus st = sync.status();
    SCOPED_TRACE(drift_ppm);
    EXPECT_EQ(st.state, SyncState::kLocked);
    EXPECT_LT(percentile(run.abs_errors_ns, 0.99), 100'000.0);
    EXPECT_NEAR(st.drift_ppm, drift_ppm, 5.0);
    // The mean delay above the envelope is the simulated jitter (exponential, mean 1 ms, capped
    // at 5 ms, plus 0.5 % spikes of 50 ms): about 1.2 ms.
    EXPECT_GT(st.jitter.ns, 700'000);
    EXPECT_LT(st.jitter.ns, 1'800'000);
    EXPECT_GT(st.uncertainty.ns, 0);
    EXPECT_LT(st.uncertainty.ns, 50'000);
    EXPECT_EQ(st.resets, 0u);
    EXPECT_EQ(st.jumps, 0u);
    EXPECT_EQ(st.locks, 1u);
    // 5 ms of jitter at a 5 ms period overtakes samples: arrivals come out of order.
    EXPECT_GT(st.out_of_order, 0u);
    EXPECT_EQ(count(run.events, ClockEvent::kLocked), 1u);
    EXPECT_EQ(run.events.size(), 1u);
    EXPECT_EQ(st.samples, samples.size());
  }
}

TEST(ClockSync, ConvergesOnSlowCameraClock) {
  const auto sim = harsh_stream(DeviceClockKind::kHardwareNs, 15.0, -100.0, 11);
  const auto samples = simulate_stream(sim, Duration::from_s(40));
  ClockSync sync(config_for(sim));
  const FeedResult run = feed(sync, samples, false, Duration::from_s(10));
  EXPECT_EQ(sync.status().state, SyncState::kLocked);
  EXPECT_LT(percentile(run.abs_errors_ns, 0.99), 100'000.0);
  EXPECT_NEAR(sync.status().drift_ppm, -100.0, 10.0);
}

TEST(ClockSync, OffsetReportsHostMinusDeviceTime) {
  auto sim = harsh_stream(DeviceClockKind::kHardwareNs, 100.0, 0.0, 3);
  sim.device_start = DeviceTime::from_ns(5'000'000'000);
  sim.host_start = HostTime::from_ns(12'000'000'000);
  const auto samples = simulate_stream(sim, Duration::from_s(5));
  ClockSync sync(config_for(sim));
  feed(sync, samples, false, Duration::from_s(0));
  EXPECT_NEAR(static_cast<double>(sync.status().offset.ns), 7e9, 100'000.0);
  // to_host() agrees with map() for a stamp it has not seen.
  const HostTime h = sync.to_host(DeviceTime::from_ns(9'000'000'000));
  EXPECT_NEAR(static_cast<double>(h.ns), 16e9, 100'000.0);
}

TEST(ClockSync, UnwrapsThe32BitCounterAcrossItsWrap) {
  auto sim = harsh_stream(DeviceClockKind::kCounterUs32Bit, 150.0, 60.0, 21);
  // The A9's µs counter wraps 8 s into the run.
  sim.device_start = DeviceTime::from_ns(
      static_cast<std::int64_t>((std::uint64_t{1} << 32) * 1000) - Duration::from_s(8).ns);
  const auto samples = simulate_stream(sim, Duration::from_s(25));
  ClockSync sync(config_for(sim));
  const FeedResult run = feed(sync, samples, true, Duration::from_s(10));
  const auto st = sync.status();
  EXPECT_EQ(st.wraps, 1u);
  EXPECT_EQ(count(run.events, ClockEvent::kCounterWrap), 1u);
  EXPECT_EQ(st.resets, 0u);
  EXPECT_EQ(st.jumps, 0u);
  EXPECT_EQ(st.state, SyncState::kLocked);
  EXPECT_LT(percentile(run.abs_errors_ns, 0.99), 100'000.0);
}

TEST(ClockSync, ResolvesTheHourRolloverOfMicrosecondsPastTheHour) {
  auto sim = harsh_stream(DeviceClockKind::kUsPastHour, 754.0, -40.0, 5);
  sim.device_start = DeviceTime::from_ns(Duration::from_s(3600 * 5 - 15).ns);  // 14:59:45
  const auto samples = simulate_stream(sim, Duration::from_s(30));
  ClockSync sync(config_for(sim));
  const FeedResult run = feed(sync, samples, true, Duration::from_s(10));
  const auto st = sync.status();
  EXPECT_EQ(st.wraps, 1u);
  EXPECT_EQ(count(run.events, ClockEvent::kHourRollover), 1u);
  EXPECT_EQ(st.resets + st.jumps, 0u);
  EXPECT_LT(percentile(run.abs_errors_ns, 0.99), 100'000.0);
}

TEST(ClockSync, DetectsADeviceResetReportsItOnceAndRelocks) {
  auto sim = harsh_stream(DeviceClockKind::kCounterUs32Bit, 200.0, 80.0, 99);
  sim.device_start = DeviceTime::from_ns(Duration::from_s(1000).ns);
  sim.reset_after = Duration::from_s(15);
  sim.device_after_reset = DeviceTime::from_ns(0);
  const auto samples = simulate_stream(sim, Duration::from_s(30));
  const HostTime reset_at = sim.host_start + sim.reset_after;
  ClockSync sync(config_for(sim));
  // Judge everything after 10 s except the 2 s the issue allows for re-locking.
  const FeedResult run =
      feed(sync, samples, true, Duration::from_s(10), reset_at, reset_at + Duration::from_s(2));
  const auto st = sync.status();
  EXPECT_EQ(st.resets, 1u);
  EXPECT_EQ(count(run.events, ClockEvent::kReset), 1u);
  EXPECT_EQ(count(run.events, ClockEvent::kLocked), 2u);
  EXPECT_EQ(st.locks, 2u);
  EXPECT_EQ(st.state, SyncState::kLocked);
  EXPECT_LT(percentile(run.abs_errors_ns, 0.99), 100'000.0);
  // The drift estimate survives the reset.
  EXPECT_NEAR(st.drift_ppm, 80.0, 10.0);
}

TEST(ClockSync, DetectsAForwardJumpOfDeviceTime) {
  auto sim = harsh_stream(DeviceClockKind::kHardwareNs, 200.0, 20.0, 4);
  sim.device_start = DeviceTime::from_ns(Duration::from_s(100).ns);
  sim.reset_after = Duration::from_s(12);
  // e.g. the D435i's clock re-synchronised: device time leaps 3 s ahead.
  sim.device_after_reset = DeviceTime::from_ns(Duration::from_s(115).ns);
  const auto samples = simulate_stream(sim, Duration::from_s(20));
  ClockSync sync(config_for(sim));
  const HostTime jump_at = sim.host_start + sim.reset_after;
  const FeedResult run =
      feed(sync, samples, false, Duration::from_s(10), jump_at, jump_at + Duration::from_s(2));
  EXPECT_EQ(sync.status().jumps, 1u);
  EXPECT_EQ(sync.status().resets, 0u);
  EXPECT_EQ(count(run.events, ClockEvent::kJump), 1u);
  EXPECT_LT(percentile(run.abs_errors_ns, 0.99), 100'000.0);
}

TEST(ClockSync, APersistentStepUpIsLostThenConfirmedAsAJump) {
  // The transport latency grows by 30 ms for good (or device time steps back by 30 ms): single
  // samples that high are spikes, a run of them is a new regime.
  auto sim = harsh_stream(DeviceClockKind::kHardwareNs, 200.0, 0.0, 8);
  sim.spike_probability = 0.0;
  auto samples = simulate_stream(sim, Duration::from_s(16));
  const HostTime step_at = sim.host_start + Duration::from_s(8);
  for (auto& s : samples) {
    if (s.true_stamp >= step_at) s.arrival += Duration::from_ms(30);
  }
  std::stable_sort(samples.begin(), samples.end(),
                   [](const auto& a, const auto& b) { return a.arrival < b.arrival; });
  ClockSync sync(config_for(sim));
  const FeedResult run = feed(sync, samples, false, Duration::from_s(0));
  EXPECT_EQ(count(run.events, ClockEvent::kLost), 1u);
  EXPECT_EQ(count(run.events, ClockEvent::kJump), 1u);
  EXPECT_EQ(sync.status().jumps, 1u);
  EXPECT_EQ(sync.status().state, SyncState::kLocked);
}

TEST(ClockSync, SingleSpikesDoNotDisturbTheEstimate) {
  auto sim = harsh_stream(DeviceClockKind::kHardwareNs, 200.0, 50.0, 12);
  sim.spike_probability = 0.02;  // four times the rate
  const auto samples = simulate_stream(sim, Duration::from_s(20));
  ClockSync sync(config_for(sim));
  const FeedResult run = feed(sync, samples, false, Duration::from_s(10));
  EXPECT_EQ(sync.status().jumps, 0u);
  EXPECT_LT(percentile(run.abs_errors_ns, 0.99), 100'000.0);
}

TEST(ClockSync, ReportsLostWhenTheStreamGoesQuiet) {
  ClockSyncConfig c;
  ClockSync sync(c);
  EXPECT_EQ(sync.status(HostTime::from_ns(0)).state, SyncState::kLost);
  sync.map(DeviceTime::from_ns(10), HostTime::from_ns(1'000'000));
  EXPECT_EQ(sync.status(HostTime::from_ns(2'000'000)).state, SyncState::kConverging);
  EXPECT_EQ(sync.status(HostTime::from_ns(1'000'000) + c.lost_after + Duration::from_ns(1)).state,
            SyncState::kLost);
}

TEST(ClockSync, BadInputIsCountedNotFatal) {
  ClockSyncConfig none;
  none.kind = DeviceClockKind::kNone;
  none.latency = Duration::from_ms(2);
  ClockSync clockless(none);
  EXPECT_EQ(clockless.map_raw(5, HostTime::from_ns(10'000'000)).ns, 8'000'000);
  EXPECT_EQ(clockless.status().rejected, 1u);

  ClockSyncConfig hour;
  hour.kind = DeviceClockKind::kUsPastHour;
  ClockSync sync(hour);
  sync.map_raw(1'000, HostTime::from_ns(5'000'000));
  sync.map_raw(3'600'000'001ull, HostTime::from_ns(6'000'000));  // beyond the hour
  EXPECT_EQ(sync.status().rejected, 1u);
  EXPECT_EQ(sync.status().samples, 1u);

  // Degenerate configuration: still no crash, estimates still come out.
  ClockSyncConfig tiny;
  tiny.window_bins = 0;
  tiny.bin_width = Duration::from_ns(0);
  ClockSync odd(tiny);
  for (int i = 0; i < 100; ++i) {
    odd.map(DeviceTime::from_ns(i * 1'000'000), HostTime::from_ns(i * 1'000'000 + 500));
  }
  EXPECT_EQ(odd.to_host(DeviceTime::from_ns(50'000'000)).ns, 50'000'500);
}

// Bit flips in an unchecksummed packet's stamp (a Velodyne data packet): single samples far off
// the line, in both directions and in a burst, none of which the samples after them confirm. None
// restarts the estimate; each is stamped from its arrival and reported as an outlier; every good
// sample stays as accurate as without them.
TEST(ClockSync, CorruptStampsAreOutliersNotResetsOrJumps) {
  auto sim = harsh_stream(DeviceClockKind::kUsPastHour, 1507.0, 20.0, 31);
  const auto clean = simulate_stream(sim, Duration::from_s(20));
  std::vector<SimulatedSample> corrupt = clean;
  std::mt19937_64 random(5);
  std::vector<bool> flipped(corrupt.size(), false);
  for (std::size_t i = 3000; i < corrupt.size(); ++i) {
    // 1 in 200 samples, and a burst of 30 in a row at 12 s, get one of the stamp's bits flipped
    const bool burst = i >= 18'000 && i < 18'030;
    if (!burst && random() % 200 != 0) continue;
    // 0.5 s to 18 min off: beyond any transport delay either way. (A flip of a few ms is
    // indistinguishable from a late packet by timing alone and stays one.)
    const auto bit = 19 + random() % 12;
    corrupt[i].raw ^= 1ull << bit;
    if (corrupt[i].raw >= 3'600'000'000ull) corrupt[i].raw %= 3'600'000'000ull;
    flipped[i] = true;
  }
  ClockSync reference(config_for(sim)), sync(config_for(sim));
  std::size_t flips = 0;
  std::vector<double> extra_error_ns;
  for (std::size_t i = 0; i < corrupt.size(); ++i) {
    const HostTime good = reference.map_raw(clean[i].raw, clean[i].arrival);
    const HostTime got = sync.map_raw(corrupt[i].raw, corrupt[i].arrival);
    if (flipped[i]) {
      ++flips;
      EXPECT_EQ(sync.last_event(), ClockEvent::kOutlier) << i;
      EXPECT_EQ(got, corrupt[i].arrival - sim.latency) << i;
    } else if (i > 3000) {
      extra_error_ns.push_back(std::abs(static_cast<double>((got - good).ns)));
    }
  }
  EXPECT_GT(flips, 100u);
  EXPECT_EQ(sync.status().resets, 0u);
  EXPECT_EQ(sync.status().jumps, 0u);
  EXPECT_EQ(sync.status().outliers, flips);
  EXPECT_EQ(sync.status().state, SyncState::kLocked);
  EXPECT_LT(percentile(extra_error_ns, 0.99), 20'000.0) << "[ns] against the uncorrupted run";
}

TEST(ClockSync, IsDeterministic) {
  const auto sim = harsh_stream(DeviceClockKind::kHardwareNs, 200.0, 30.0, 77);
  const auto samples = simulate_stream(sim, Duration::from_s(5));
  ClockSync a(config_for(sim)), b(config_for(sim));
  for (const auto& s : samples) {
    ASSERT_EQ(a.map(s.device_stamp, s.arrival), b.map(s.device_stamp, s.arrival));
  }
}

}  // namespace
}  // namespace posed

namespace posed {
namespace {

TEST(ClockSync, AStragglerFromBeforeAResetIsStampedOnTheOldLineNotAnotherReset) {
  ClockSyncConfig c;
  ClockSync sync(c);
  // Device clock = host - 7 s, 200 Hz, 1 ms latency, until a reset at host 10 s to device 0.
  for (std::int64_t k = 0; k < 2000; ++k) {
    const std::int64_t t = 1'000'000'000 + k * 5'000'000;
    sync.map(DeviceTime::from_ns(t - 7'000'000'000), HostTime::from_ns(t + 1'000'000));
  }
  const std::int64_t reset_host = 11'000'000'000;
  // The reset's first samples are outliers until the third confirms the new line.
  for (std::int64_t k = 0; k < 3; ++k) {
    sync.map(DeviceTime::from_ns(k * 5'000'000),
             HostTime::from_ns(reset_host + 1'000'000 + k * 5'000'000));
    EXPECT_EQ(sync.last_event(), k < 2 ? ClockEvent::kOutlier : ClockEvent::kReset) << k;
  }
  // A sample taken just before the reset arrives 40 ms late.
  const std::int64_t late_truth = reset_host - 5'000'000;
  const HostTime late = sync.map(DeviceTime::from_ns(late_truth - 7'000'000'000),
                                 HostTime::from_ns(late_truth + 40'000'000));
  EXPECT_EQ(sync.last_event(), ClockEvent::kNone);
  // The old line (latency not configured here, so stamps sit 1 ms after the truth).
  EXPECT_NEAR(static_cast<double>(late.ns), static_cast<double>(late_truth + 1'000'000), 1'000.0);
  sync.map(DeviceTime::from_ns(15'000'000), HostTime::from_ns(reset_host + 16'000'000));
  EXPECT_EQ(sync.last_event(), ClockEvent::kNone);
  EXPECT_EQ(sync.status().resets, 1u);
  EXPECT_EQ(sync.status().jumps, 0u);
}

}  // namespace
}  // namespace posed
