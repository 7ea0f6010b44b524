#include "core/sync/stream_pairer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "core/measurements.hpp"
#include "core/payload_pool.hpp"

namespace posed {
// Named rather than anonymous: test binaries build as unity batches, where another file's
// helpers of the same name share the translation unit.
namespace stream_pairer_test {

HostTime ms(std::int64_t v) { return HostTime::from_ns(Duration::from_ms(v).ns); }
HostTime us(std::int64_t v) { return HostTime::from_ns(Duration::from_us(v).ns); }

/// A small copyable payload for the rule tests (the pairer is generic over the payload).
struct Frame {
  HostTime stamp;
  int id = 0;
};

using Pairer = StreamPairer<Frame, Frame>;
using Out = FramePair<Frame, Frame>;

Frame frame(std::int64_t stamp_ms, int id) { return Frame{ms(stamp_ms), id}; }

std::vector<Out> drain(Pairer& p, std::optional<HostTime> watermark = std::nullopt) {
  std::vector<Out> out;
  while (auto r = p.pop(watermark)) out.push_back(std::move(*r));
  return out;
}

// ---------------------------------------------------------------------------------------------
// 15 Hz visible and 25 Hz thermal frames, ±3 ms stamp jitter, 10 % of each stream lost, arrival
// latency 30 ms (visible) / 12 ms (thermal) plus up to 20 ms of jitter, interleaved by arrival.

struct Stamped {
  HostTime stamp;
  HostTime arrival;
  bool visible = false;
  std::uint64_t id = 0;
};

struct Streams {
  std::vector<HostTime> visible;
  std::vector<HostTime> thermal;
  std::vector<Stamped> arrivals;
};

Streams make_streams(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto jitter_us = [&](std::int64_t max_abs) {
    return static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(2 * max_abs + 1)) - max_abs;
  };
  Streams s;
  for (std::int64_t k = 0; k < 150; ++k) {  // 10 s at 15 Hz
    const HostTime stamp = us(k * 1'000'000 / 15 + jitter_us(3'000));
    if (rng() % 10 == 0) continue;
    s.visible.push_back(stamp);
    s.arrivals.push_back({stamp, stamp + Duration::from_us(30'000 + jitter_us(10'000) + 10'000),
                          true, s.visible.size() - 1});
  }
  for (std::int64_t k = 0; k < 250; ++k) {  // 10 s at 25 Hz, offset 7 ms
    const HostTime stamp = us(7'000 + k * 40'000 + jitter_us(3'000));
    if (rng() % 10 == 0) continue;
    s.thermal.push_back(stamp);
    s.arrivals.push_back({stamp, stamp + Duration::from_us(12'000 + jitter_us(10'000) + 10'000),
                          false, s.thermal.size() - 1});
  }
  std::stable_sort(s.arrivals.begin(), s.arrivals.end(),
                   [](const Stamped& a, const Stamped& b) { return a.arrival < b.arrival; });
  return s;
}

Duration distance(HostTime a, HostTime b) { return a < b ? b - a : a - b; }

TEST(StreamPairer, PairsFifteenAndTwentyFiveHertzByNearestStampWithinTolerance) {
  for (std::int64_t tolerance_ms : {5, 10, 20}) {
    for (std::uint64_t seed : {11u, 12u}) {
      SCOPED_TRACE(testing::Message() << "tolerance " << tolerance_ms << " ms, seed " << seed);
      const Streams s = make_streams(seed);
      const Duration tol = Duration::from_ms(tolerance_ms);
      PayloadPool pool(64, 16);
      StreamPairer<Image, Image> pairer({tol, 8});
      // What each release carried; the releases themselves are destroyed at once, returning
      // their buffers (the pool is smaller than the run).
      struct Seen {
        std::optional<std::uint64_t> visible, thermal;
        HostTime visible_stamp, thermal_stamp;
        Duration thermal_minus_visible;
        bool leases_valid = true;
      };
      std::vector<Seen> out;
      auto record = [&out](FramePair<Image, Image>&& r) {
        Seen seen;
        if (r.visible) {
          seen.visible = r.visible->sequence;
          seen.visible_stamp = r.visible->stamp;
          seen.leases_valid = seen.leases_valid && r.visible->pixels.valid();
        }
        if (r.thermal) {
          seen.thermal = r.thermal->sequence;
          seen.thermal_stamp = r.thermal->stamp;
          seen.leases_valid = seen.leases_valid && r.thermal->pixels.valid();
        }
        seen.thermal_minus_visible = r.thermal_minus_visible;
        out.push_back(seen);
      };
      for (const Stamped& a : s.arrivals) {
        Image im;
        im.stamp = a.stamp;
        im.sequence = a.id;
        im.pixels = pool.acquire();
        ASSERT_TRUE(im.pixels.valid());
        const auto pushed =
            a.visible ? pairer.push_visible(std::move(im)) : pairer.push_thermal(std::move(im));
        ASSERT_EQ(pushed, PairerPushResult::kQueued);
        // Decisions from the frames alone while both streams flow.
        while (auto r = pairer.pop()) record(std::move(*r));
      }
      // End of stream: everything has arrived.
      while (auto r = pairer.pop(ms(20'000))) record(std::move(*r));
      EXPECT_EQ(pairer.pending_visible(), 0u);
      EXPECT_EQ(pairer.pending_thermal(), 0u);
      EXPECT_EQ(pool.in_use(), 0u);

      // Reference, by brute force over every thermal frame: each visible frame's nearest thermal
      // frame, a partner if within tolerance. (With thermal frames >= 34 ms apart and visible
      // ones >= 60 ms apart no thermal frame is within 20 ms of two visible frames, so the
      // nearest one is always still free.)
      std::vector<std::optional<std::uint64_t>> expected(s.visible.size());
      std::uint64_t expected_pairs = 0;
      for (std::size_t v = 0; v < s.visible.size(); ++v) {
        std::size_t best = 0;
        for (std::size_t t = 1; t < s.thermal.size(); ++t) {
          if (distance(s.thermal[t], s.visible[v]) < distance(s.thermal[best], s.visible[v])) {
            best = t;
          }
        }
        if (distance(s.thermal[best], s.visible[v]) <= tol) {
          expected[v] = best;
          ++expected_pairs;
        }
      }
      ASSERT_GT(expected_pairs, 10u);
      ASSERT_LT(expected_pairs, s.visible.size()) << "some frames must find no partner";

      std::vector<std::uint64_t> visible_seen;
      std::vector<std::uint64_t> thermal_seen;
      for (const Seen& r : out) {
        ASSERT_TRUE(r.visible || r.thermal);
        EXPECT_TRUE(r.leases_valid);
        if (r.visible) visible_seen.push_back(*r.visible);
        if (r.thermal) thermal_seen.push_back(*r.thermal);
        if (r.visible && r.thermal) {
          const std::uint64_t v = *r.visible;
          EXPECT_LE(distance(r.thermal_stamp, r.visible_stamp), tol) << "never beyond tolerance";
          EXPECT_EQ(r.thermal_minus_visible, r.thermal_stamp - r.visible_stamp);
          ASSERT_TRUE(expected[v].has_value()) << "visible " << v << " paired but should not be";
          EXPECT_EQ(*r.thermal, *expected[v]) << "visible " << v << ": not the nearest";
        } else if (r.visible) {
          EXPECT_FALSE(expected[*r.visible].has_value())
              << "visible " << *r.visible << " released alone but had a partner";
        }
      }
      // Every frame released exactly once, in stamp order within its stream: each thermal frame
      // is used at most once.
      ASSERT_EQ(visible_seen.size(), s.visible.size());
      ASSERT_EQ(thermal_seen.size(), s.thermal.size());
      for (std::size_t i = 0; i < visible_seen.size(); ++i) EXPECT_EQ(visible_seen[i], i);
      for (std::size_t i = 0; i < thermal_seen.size(); ++i) EXPECT_EQ(thermal_seen[i], i);

      const auto& c = pairer.counters();
      EXPECT_EQ(c.paired, expected_pairs);
      EXPECT_EQ(c.unpaired_visible, s.visible.size() - expected_pairs);
      EXPECT_EQ(c.unpaired_thermal, s.thermal.size() - expected_pairs);
      EXPECT_EQ(c.visible_overflow_dropped + c.thermal_overflow_dropped, 0u);
    }
  }
}

TEST(StreamPairer, WaitsUntilTheChoiceCannotChange) {
  Pairer p({Duration::from_ms(10), 8});
  p.push_visible(frame(100, 1));
  p.push_thermal(frame(95, 1));
  EXPECT_FALSE(p.pop().has_value()) << "a thermal frame at 96..105 could still come";
  p.push_thermal(frame(104, 2));  // nearer (4 ms vs 5 ms) and later: the choice is final
  auto a = p.pop();
  ASSERT_TRUE(a.has_value());
  EXPECT_FALSE(a->visible.has_value());
  EXPECT_EQ(a->thermal->id, 1) << "the older thermal frame goes out alone first";
  auto b = p.pop();
  ASSERT_TRUE(b && b->paired());
  EXPECT_EQ(b->visible->id, 1);
  EXPECT_EQ(b->thermal->id, 2);
  EXPECT_EQ(b->thermal_minus_visible, Duration::from_ms(4));
}

TEST(StreamPairer, WatermarkDecidesWhenTheOtherStreamIsSilent) {
  Pairer p({Duration::from_ms(10), 8});
  p.push_visible(frame(200, 1));
  EXPECT_FALSE(p.pop(ms(209)).has_value()) << "a thermal frame at 209..210 could still come";
  auto r = p.pop(ms(210));
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(r->visible && !r->thermal);
  EXPECT_EQ(p.counters().unpaired_visible, 1u);

  p.push_thermal(frame(300, 1));
  EXPECT_FALSE(p.pop(ms(309)).has_value());
  r = p.pop(ms(310));
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(!r->visible && r->thermal);
  EXPECT_EQ(p.counters().unpaired_thermal, 1u);
}

TEST(StreamPairer, NeverPairsBeyondTolerance) {
  Pairer p({Duration::from_ms(10), 8});
  p.push_thermal(frame(289, 1));
  p.push_visible(frame(300, 1));
  p.push_thermal(frame(311, 2));
  const auto out = drain(p, ms(400));
  ASSERT_EQ(out.size(), 3u);
  for (const auto& r : out) EXPECT_FALSE(r.paired());
  EXPECT_EQ(p.counters().paired, 0u);
  EXPECT_EQ(p.counters().unpaired_visible, 1u);
  EXPECT_EQ(p.counters().unpaired_thermal, 2u);
  // Exactly at the tolerance still pairs.
  Pairer q({Duration::from_ms(10), 8});
  q.push_visible(frame(300, 1));
  q.push_thermal(frame(310, 1));
  const auto paired = drain(q);
  ASSERT_EQ(paired.size(), 1u);
  EXPECT_TRUE(paired[0].paired());
}

TEST(StreamPairer, EachThermalFrameIsUsedOnceAndPairsNeverCross) {
  Pairer p({Duration::from_ms(30), 8});
  p.push_visible(frame(0, 1));
  p.push_visible(frame(12, 2));
  p.push_thermal(frame(-9, 1));
  p.push_thermal(frame(8, 2));
  p.push_thermal(frame(200, 3));
  const auto out = drain(p, ms(1000));
  // visible 0 takes thermal 8 (nearer than -9); thermal -9 is older than a used frame, so it
  // goes out alone rather than to visible 12 (within 30 ms, but that pair would cross);
  // visible 12's nearest, thermal 8, is taken: it goes out alone.
  ASSERT_EQ(out.size(), 4u);
  EXPECT_TRUE(!out[0].visible && out[0].thermal->id == 1);
  EXPECT_TRUE(out[1].paired() && out[1].visible->id == 1 && out[1].thermal->id == 2);
  EXPECT_TRUE(out[2].visible && !out[2].thermal && out[2].visible->id == 2);
  EXPECT_TRUE(!out[3].visible && out[3].thermal->id == 3);
  EXPECT_EQ(p.counters().paired, 1u);
}

TEST(StreamPairer, TieGoesToTheEarlierThermalFrame) {
  Pairer p({Duration::from_ms(10), 8});
  p.push_visible(frame(100, 1));
  p.push_thermal(frame(92, 1));
  p.push_thermal(frame(108, 2));
  auto r = p.pop();
  ASSERT_TRUE(r && r->paired());
  EXPECT_EQ(r->thermal->id, 1);
}

TEST(StreamPairer, OutOfOrderFramesAreDroppedAndCounted) {
  Pairer p({Duration::from_ms(10), 8});
  EXPECT_EQ(p.push_visible(frame(100, 1)), PairerPushResult::kQueued);
  EXPECT_EQ(p.push_visible(frame(100, 2)), PairerPushResult::kDroppedOutOfOrder);
  EXPECT_EQ(p.push_visible(frame(50, 3)), PairerPushResult::kDroppedOutOfOrder);
  EXPECT_EQ(p.push_thermal(frame(90, 1)), PairerPushResult::kQueued);
  EXPECT_EQ(p.push_thermal(frame(80, 2)), PairerPushResult::kDroppedOutOfOrder);
  EXPECT_EQ(p.counters().visible_out_of_order, 2u);
  EXPECT_EQ(p.counters().thermal_out_of_order, 1u);
  EXPECT_EQ(p.pending_visible(), 1u);
  EXPECT_EQ(p.pending_thermal(), 1u);
}

TEST(StreamPairer, OverflowDropsTheOldestPendingFrame) {
  Pairer p({Duration::from_ms(10), 2});
  p.push_visible(frame(100, 1));
  p.push_visible(frame(200, 2));
  EXPECT_EQ(p.push_visible(frame(300, 3)), PairerPushResult::kQueuedDroppedOldest);
  EXPECT_EQ(p.counters().visible_overflow_dropped, 1u);
  const auto out = drain(p, ms(1000));
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].visible->id, 2);
  EXPECT_EQ(out[1].visible->id, 3);
}

}  // namespace stream_pairer_test
}  // namespace posed
