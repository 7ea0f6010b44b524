#include "core/sync/measurement_gate.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "core/payload_pool.hpp"

namespace posed {
// Named rather than anonymous: test binaries build as unity batches, where another file's
// helpers of the same name share the translation unit.
namespace measurement_gate_test {

HostTime ms(std::int64_t v) { return HostTime::from_ns(Duration::from_ms(v).ns); }
HostTime us(std::int64_t v) { return HostTime::from_ns(Duration::from_us(v).ns); }

ImuSample imu_at(HostTime t) {
  ImuSample s;
  s.stamp = t;
  s.angular_velocity_radps = Eigen::Vector3d(0.0, 0.0, 0.1);
  s.specific_force_mps2 = Eigen::Vector3d(0.0, 0.0, 9.81);
  return s;
}

Image image_at(HostTime t, PayloadPool* pool = nullptr) {
  Image im;
  im.stamp = t;
  if (pool) im.pixels = pool->acquire();
  return im;
}

std::vector<std::int64_t> stamps_ns(const std::vector<ImuSample>& v) {
  std::vector<std::int64_t> out;
  for (const auto& s : v) out.push_back(s.stamp.ns);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Synthetic rig: 200 Hz IMU (5 % of samples lost, arrival jitter up to 8 ms so some arrive out
// of order, plus explicit swaps) and 10 Hz scans (arrival jitter up to 30 ms).

struct Event {
  HostTime arrival;
  bool is_imu = false;
  std::size_t index = 0;  ///< into imu stamps or scans
};

struct Rig {
  std::vector<HostTime> imu_stamps;  ///< samples sent, in stamp order
  std::vector<TimeSpan> scans;       ///< scan k's [start, end]
  std::vector<Event> events;         ///< arrival order
};

Rig make_rig(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Rig rig;
  const std::int64_t imu_period_us = 5'000;
  for (std::int64_t k = 0; k < 600; ++k) {  // 3 s
    if (rng() % 100 < 5) continue;          // lost sample: never arrives
    const HostTime stamp = us(1'000 + k * imu_period_us);
    rig.imu_stamps.push_back(stamp);
    const std::int64_t jitter_us = static_cast<std::int64_t>(rng() % 8'000);
    rig.events.push_back(
        {stamp + Duration::from_us(500 + jitter_us), true, rig.imu_stamps.size() - 1});
  }
  for (std::int64_t k = 0; k < 28; ++k) {
    const HostTime start = us(3'000 + k * 100'000);
    const HostTime end = start + Duration::from_us(99'900);
    rig.scans.push_back({start, end});
    const std::int64_t jitter_us = static_cast<std::int64_t>(rng() % 30'000);
    rig.events.push_back(
        {end + Duration::from_us(15'000 + jitter_us), false, rig.scans.size() - 1});
  }
  std::stable_sort(rig.events.begin(), rig.events.end(),
                   [](const Event& a, const Event& b) { return a.arrival < b.arrival; });
  // A few adjacent IMU arrivals swapped outright (a USB burst delivered backwards).
  for (std::size_t i = 50; i + 1 < rig.events.size(); i += 97) {
    if (rig.events[i].is_imu && rig.events[i + 1].is_imu)
      std::swap(rig.events[i], rig.events[i + 1]);
  }
  return rig;
}

struct Released {
  std::uint64_t sequence = 0;
  std::size_t event_index = 0;
  TimeSpan imu_span;
  ImuRange range;
  ReleaseKind kind = ReleaseKind::kCovered;
  std::vector<std::int64_t> imu_ns;
  bool lease_valid = false;
};

TEST(MeasurementGate, ScanBundlesHoldExactlyTheImuSpanningEachScan) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    const Rig rig = make_rig(seed);
    PayloadPool pool(8, 64);
    ImuBuffer imu({400, ImuOrderPolicy::kDrop});
    MeasurementGate<LidarScan> gate({4, LatePolicy::kDrop});
    std::vector<ImuSample> bundle_imu;
    bundle_imu.reserve(imu.capacity());
    std::vector<Released> released;

    // Reference, computed independently of the buffer: which samples the kDrop policy keeps
    // (those newer than everything that arrived before them), the newest kept stamp after each
    // event, and whether each scan has arrived.
    std::vector<HostTime> kept;
    std::vector<HostTime> newest_after_event(rig.events.size());
    std::vector<std::size_t> scan_arrival_event(rig.scans.size());
    std::optional<HostTime> newest;
    std::uint64_t expected_out_of_order = 0;

    for (std::size_t e = 0; e < rig.events.size(); ++e) {
      const Event& ev = rig.events[e];
      if (ev.is_imu) {
        const HostTime stamp = rig.imu_stamps[ev.index];
        if (!newest || stamp > *newest) {
          kept.push_back(stamp);
          newest = stamp;
        } else {
          ++expected_out_of_order;
        }
        imu.push(imu_at(stamp));
      } else {
        scan_arrival_event[ev.index] = e;
        LidarScan scan;
        scan.start_stamp = rig.scans[ev.index].begin;
        scan.end_stamp = rig.scans[ev.index].end;
        scan.sequence = ev.index;
        scan.points = pool.acquire();
        ASSERT_EQ(gate.push(std::move(scan)), GatePushResult::kQueued);
      }
      newest_after_event[e] = newest.value_or(HostTime::from_ns(-1));
      while (auto b = gate.pop_ready(imu, bundle_imu)) {
        released.push_back({b->measurement.sequence, e, b->imu_span, b->imu, b->kind,
                            stamps_ns(bundle_imu), b->measurement.points.valid()});
      }
      // The caller's IMU housekeeping: keep only what the gate may still ask for.
      if (auto t = gate.oldest_needed()) imu.discard_before(*t);
    }

    ASSERT_GT(expected_out_of_order, 0u) << "the rig must exercise out-of-order IMU arrivals";
    EXPECT_EQ(imu.counters().out_of_order_dropped, expected_out_of_order);
    EXPECT_EQ(imu.counters().overwritten, 0u);

    // Every scan whose end the IMU reached is released, in order, with its lease.
    std::size_t coverable = 0;
    for (const auto& s : rig.scans) coverable += (s.end <= kept.back()) ? 1 : 0;
    ASSERT_EQ(released.size(), coverable);
    ASSERT_GE(released.size(), 25u);
    EXPECT_EQ(gate.counters().released, released.size());
    EXPECT_EQ(gate.pending(), rig.scans.size() - coverable);

    for (std::size_t k = 0; k < released.size(); ++k) {
      SCOPED_TRACE(k);
      const Released& r = released[k];
      EXPECT_EQ(r.sequence, k);
      EXPECT_TRUE(r.lease_valid);
      EXPECT_EQ(r.kind, ReleaseKind::kCovered);
      const TimeSpan scan = rig.scans[k];
      // Interval: from the previous scan's end (or this scan's start for the first) to its end.
      const HostTime begin = k == 0 ? scan.begin : std::min(scan.begin, rig.scans[k - 1].end);
      EXPECT_EQ(r.imu_span.begin, begin);
      EXPECT_EQ(r.imu_span.end, scan.end);

      // Exactly the kept samples inside, plus the newest kept before and the oldest kept after.
      std::vector<std::int64_t> expected;
      auto first_inside = std::lower_bound(kept.begin(), kept.end(), begin);
      if (first_inside != kept.begin()) expected.push_back(std::prev(first_inside)->ns);
      auto past_inside = std::upper_bound(kept.begin(), kept.end(), scan.end);
      for (auto it = first_inside; it != past_inside; ++it) expected.push_back(it->ns);
      if (past_inside != kept.end()) expected.push_back(past_inside->ns);
      EXPECT_EQ(r.imu_ns, expected);
      EXPECT_EQ(r.range.count, expected.size());
      if (k > 0) {
        EXPECT_TRUE(r.range.covers_begin);
        EXPECT_TRUE(r.range.has_before);
      }
      EXPECT_TRUE(r.range.covers_end);
      EXPECT_TRUE(r.range.has_after);

      // Released at the first event after which the scan had arrived and the IMU covered it.
      std::size_t first_ready = scan_arrival_event[k];
      while (newest_after_event[first_ready] < scan.end) ++first_ready;
      // In-order release: a scan cannot go before its predecessor.
      if (k > 0) first_ready = std::max(first_ready, released[k - 1].event_index);
      EXPECT_EQ(r.event_index, first_ready);
    }
    released.clear();
    EXPECT_EQ(pool.in_use(), gate.pending()) << "released scans returned their buffers";
  }
}

TEST(MeasurementGate, WaitsForTheImuAndReleasesAsSoonAsItCovers) {
  ImuBuffer imu({64, ImuOrderPolicy::kDrop});
  MeasurementGate<Image> gate({4, LatePolicy::kDrop});
  std::vector<ImuSample> out;
  imu.push(imu_at(ms(90)));
  EXPECT_EQ(gate.push(image_at(ms(100))), GatePushResult::kQueued);
  EXPECT_FALSE(gate.pop_ready(imu, out).has_value());
  imu.push(imu_at(ms(95)));
  EXPECT_FALSE(gate.pop_ready(imu, out).has_value());
  imu.push(imu_at(HostTime::from_ns(ms(100).ns - 1)));
  EXPECT_FALSE(gate.pop_ready(imu, out).has_value()) << "one ns short of covering";
  imu.push(imu_at(ms(100)));  // IMU time == measurement time: covered
  auto b = gate.pop_ready(imu, out);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->measurement.stamp, ms(100));
  EXPECT_EQ(b->kind, ReleaseKind::kCovered);
  EXPECT_FALSE(gate.pop_ready(imu, out).has_value());

  // Already covered when it arrives: released at the first pop.
  EXPECT_EQ(gate.push(image_at(ms(97))), GatePushResult::kLateDropped);
  imu.push(imu_at(ms(130)));
  gate.push(image_at(ms(120)));
  b = gate.pop_ready(imu, out);
  ASSERT_TRUE(b.has_value());
  // The image bundle runs from the previous release (100 ms) to this one: seed 002's packaging.
  EXPECT_EQ(b->imu_span.begin, ms(100));
  EXPECT_EQ(b->imu_span.end, ms(120));
  EXPECT_EQ(stamps_ns(out), (std::vector<std::int64_t>{ms(100).ns - 1, ms(100).ns, ms(130).ns}));
}

TEST(MeasurementGate, LateDropPolicyCountsAndDiscards) {
  PayloadPool pool(4, 16);
  ImuBuffer imu({64, ImuOrderPolicy::kDrop});
  MeasurementGate<Image> gate({4, LatePolicy::kDrop});
  std::vector<ImuSample> out;
  imu.push(imu_at(ms(300)));
  gate.push(image_at(ms(200), &pool));
  ASSERT_TRUE(gate.pop_ready(imu, out).has_value());
  EXPECT_EQ(gate.push(image_at(ms(150), &pool)), GatePushResult::kLateDropped);
  EXPECT_EQ(gate.push(image_at(ms(200), &pool)), GatePushResult::kQueued)
      << "the same stamp as the last released is not late";
  EXPECT_EQ(gate.counters().late_dropped, 1u);
  EXPECT_EQ(pool.in_use(), 1u) << "the dropped image returned its buffer";
  EXPECT_EQ(gate.counters().late_released, 0u);
}

TEST(MeasurementGate, LateReleasePolicyReleasesAtOnceFlaggedAndCounted) {
  ImuBuffer imu({64, ImuOrderPolicy::kDrop});
  for (std::int64_t t = 100; t <= 200; t += 5) imu.push(imu_at(ms(t)));
  MeasurementGate<Image> gate({4, LatePolicy::kRelease});
  std::vector<ImuSample> out;
  gate.push(image_at(ms(180)));
  ASSERT_TRUE(gate.pop_ready(imu, out).has_value());
  gate.push(image_at(ms(260)));  // not covered yet: waits
  EXPECT_EQ(gate.push(image_at(ms(152))), GatePushResult::kLateQueued);
  auto b = gate.pop_ready(imu, out);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->kind, ReleaseKind::kLate);
  EXPECT_EQ(b->measurement.stamp, ms(152));
  // Its own span only, with whatever IMU is held.
  EXPECT_EQ(b->imu_span.begin, ms(152));
  EXPECT_EQ(stamps_ns(out), (std::vector<std::int64_t>{ms(150).ns, ms(155).ns}));
  EXPECT_EQ(gate.counters().late_released, 1u);
  EXPECT_EQ(gate.last_released(), ms(180)) << "the release point does not move backwards";
  EXPECT_FALSE(gate.pop_ready(imu, out).has_value()) << "260 ms is still not covered";
  imu.push(imu_at(ms(260)));
  b = gate.pop_ready(imu, out);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->kind, ReleaseKind::kCovered);
  EXPECT_EQ(b->imu_span.begin, ms(180));
}

TEST(MeasurementGate, OverflowDropsTheOldestAndReturnsItsBuffer) {
  PayloadPool pool(4, 16);
  ImuBuffer imu({64, ImuOrderPolicy::kDrop});
  MeasurementGate<Image> gate({2, LatePolicy::kDrop});
  std::vector<ImuSample> out;
  EXPECT_EQ(gate.push(image_at(ms(100), &pool)), GatePushResult::kQueued);
  EXPECT_EQ(gate.push(image_at(ms(200), &pool)), GatePushResult::kQueued);
  EXPECT_EQ(gate.push(image_at(ms(300), &pool)), GatePushResult::kQueuedDroppedOldest);
  EXPECT_EQ(pool.in_use(), 2u);
  EXPECT_EQ(gate.push(image_at(ms(50), &pool)), GatePushResult::kDroppedOverflow)
      << "older than everything pending: it is the oldest";
  EXPECT_EQ(gate.counters().overflow_dropped, 2u);
  EXPECT_EQ(pool.in_use(), 2u);
  imu.push(imu_at(ms(400)));
  auto a = gate.pop_ready(imu, out);
  auto b = gate.pop_ready(imu, out);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->measurement.stamp, ms(200));
  EXPECT_EQ(b->measurement.stamp, ms(300));
  EXPECT_TRUE(a->measurement.pixels.valid());
}

TEST(MeasurementGate, OutOfOrderPendingMeasurementsAreReleasedInStampOrderAndCounted) {
  ImuBuffer imu({64, ImuOrderPolicy::kDrop});
  MeasurementGate<Image> gate({4, LatePolicy::kDrop});
  std::vector<ImuSample> out;
  gate.push(image_at(ms(200)));
  gate.push(image_at(ms(100)));
  EXPECT_EQ(gate.counters().out_of_order, 1u);
  imu.push(imu_at(ms(150)));
  auto a = gate.pop_ready(imu, out);
  ASSERT_TRUE(a.has_value());
  EXPECT_EQ(a->measurement.stamp, ms(100));
  EXPECT_FALSE(gate.pop_ready(imu, out).has_value());
  imu.push(imu_at(ms(200)));
  auto b = gate.pop_ready(imu, out);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->measurement.stamp, ms(200));
}

TEST(MeasurementGate, DrainReleasesUncoveredAtEndOfStreamFlagged) {
  ImuBuffer imu({64, ImuOrderPolicy::kDrop});
  imu.push(imu_at(ms(100)));
  MeasurementGate<Image> gate({4, LatePolicy::kDrop});
  std::vector<ImuSample> out;
  gate.push(image_at(ms(90)));
  gate.push(image_at(ms(150)));
  auto a = gate.pop_drain(imu, out);
  ASSERT_TRUE(a.has_value());
  EXPECT_EQ(a->kind, ReleaseKind::kCovered);
  auto b = gate.pop_drain(imu, out);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->kind, ReleaseKind::kDrained);
  EXPECT_FALSE(b->imu.covers_end);
  EXPECT_FALSE(gate.pop_drain(imu, out).has_value());
  EXPECT_EQ(gate.counters().drained_uncovered, 1u);
}

TEST(MeasurementGate, OldestNeededTracksPendingSpansAndTheLastRelease) {
  ImuBuffer imu({64, ImuOrderPolicy::kDrop});
  MeasurementGate<LidarScan> gate({4, LatePolicy::kDrop});
  std::vector<ImuSample> out;
  EXPECT_FALSE(gate.oldest_needed().has_value());
  LidarScan s;
  s.start_stamp = ms(100);
  s.end_stamp = ms(200);
  gate.push(std::move(s));
  EXPECT_EQ(gate.oldest_needed(), ms(100));
  imu.push(imu_at(ms(210)));
  ASSERT_TRUE(gate.pop_ready(imu, out).has_value());
  EXPECT_EQ(gate.oldest_needed(), ms(200));
}

}  // namespace measurement_gate_test
}  // namespace posed
