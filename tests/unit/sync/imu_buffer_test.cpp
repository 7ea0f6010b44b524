#include "core/sync/imu_buffer.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace posed {
namespace {

ImuSample sample_at(std::int64_t ms, double value = 0.0) {
  ImuSample s;
  s.stamp = HostTime::from_ns(Duration::from_ms(ms).ns);
  s.device_stamp = DeviceTime::from_ns(Duration::from_ms(ms).ns + 1000);
  s.angular_velocity_radps = Eigen::Vector3d(value, 2.0 * value, -value);
  s.specific_force_mps2 = Eigen::Vector3d(0.0, value, 9.81 + value);
  return s;
}

HostTime ms(std::int64_t v) { return HostTime::from_ns(Duration::from_ms(v).ns); }

std::vector<std::int64_t> stamps_ms(const std::vector<ImuSample>& v) {
  std::vector<std::int64_t> out;
  for (const auto& s : v) out.push_back(s.stamp.ns / 1'000'000);
  return out;
}

/// Samples every 5 ms from 0 to 50 ms.
ImuBuffer filled(std::size_t capacity = 64) {
  ImuBuffer buf({capacity, ImuOrderPolicy::kDrop});
  for (std::int64_t t = 0; t <= 50; t += 5) buf.push(sample_at(t, static_cast<double>(t)));
  return buf;
}

TEST(ImuBuffer, DropsOutOfOrderAndDuplicateSamplesAndCountsThem) {
  ImuBuffer buf({8, ImuOrderPolicy::kDrop});
  EXPECT_EQ(buf.push(sample_at(10)), ImuPushResult::kAccepted);
  EXPECT_EQ(buf.push(sample_at(20)), ImuPushResult::kAccepted);
  EXPECT_EQ(buf.push(sample_at(15)), ImuPushResult::kDroppedOutOfOrder);
  EXPECT_EQ(buf.push(sample_at(20)), ImuPushResult::kDroppedDuplicate);
  EXPECT_EQ(buf.push(sample_at(25)), ImuPushResult::kAccepted);
  EXPECT_EQ(buf.size(), 3u);
  EXPECT_EQ(buf.counters().accepted, 3u);
  EXPECT_EQ(buf.counters().out_of_order_dropped, 1u);
  EXPECT_EQ(buf.counters().duplicate_dropped, 1u);
  EXPECT_EQ(buf[1].stamp, ms(20));
}

TEST(ImuBuffer, OverwritesOldestWhenFullAndCountsIt) {
  ImuBuffer buf({4, ImuOrderPolicy::kDrop});
  for (std::int64_t t = 0; t < 4; ++t) EXPECT_EQ(buf.push(sample_at(t)), ImuPushResult::kAccepted);
  EXPECT_EQ(buf.push(sample_at(4)), ImuPushResult::kAcceptedOverwrote);
  EXPECT_EQ(buf.push(sample_at(5)), ImuPushResult::kAcceptedOverwrote);
  EXPECT_EQ(buf.size(), 4u);
  EXPECT_EQ(buf.oldest_stamp(), ms(2));
  EXPECT_EQ(buf.newest_stamp(), ms(5));
  EXPECT_EQ(buf.counters().overwritten, 2u);
  // Order survives the wrap of the ring.
  for (std::size_t i = 0; i < buf.size(); ++i) {
    EXPECT_EQ(buf[i].stamp, ms(static_cast<std::int64_t>(i) + 2));
  }
}

TEST(ImuBuffer, ZeroCapacityStoresNothing) {
  ImuBuffer buf({0, ImuOrderPolicy::kDrop});
  EXPECT_EQ(buf.push(sample_at(1)), ImuPushResult::kDroppedNoCapacity);
  EXPECT_FALSE(buf.covers(ms(0)));
  std::vector<ImuSample> out;
  EXPECT_EQ(buf.samples_between(ms(0), ms(10), out).count, 0u);
}

TEST(ImuBuffer, CoversMeansNewestStampAtOrAfter) {
  ImuBuffer buf({8, ImuOrderPolicy::kDrop});
  EXPECT_FALSE(buf.covers(ms(0)));
  buf.push(sample_at(10));
  EXPECT_TRUE(buf.covers(ms(10)));
  EXPECT_TRUE(buf.covers(ms(3)));
  EXPECT_FALSE(buf.covers(HostTime::from_ns(ms(10).ns + 1)));
}

TEST(ImuBuffer, SamplesBetweenReturnsInsideSamplesPlusBothBrackets) {
  const ImuBuffer buf = filled();
  std::vector<ImuSample> out;
  // Interior interval not on sample stamps: 10..30 inside, brackets 10 and 30.
  ImuRange r = buf.samples_between(ms(12), ms(28), out);
  EXPECT_EQ(stamps_ms(out), (std::vector<std::int64_t>{10, 15, 20, 25, 30}));
  EXPECT_EQ(r.count, 5u);
  EXPECT_TRUE(r.has_before);
  EXPECT_TRUE(r.has_after);
  EXPECT_TRUE(r.covers_begin);
  EXPECT_TRUE(r.covers_end);

  // Ends on sample stamps: the brackets are still added (no special case).
  r = buf.samples_between(ms(15), ms(25), out);
  EXPECT_EQ(stamps_ms(out), (std::vector<std::int64_t>{10, 15, 20, 25, 30}));
  EXPECT_TRUE(r.has_before);
  EXPECT_TRUE(r.has_after);

  // An interval between two samples: only the two brackets.
  r = buf.samples_between(ms(21), ms(24), out);
  EXPECT_EQ(stamps_ms(out), (std::vector<std::int64_t>{20, 25}));

  // An instant: brackets around it.
  r = buf.samples_between(ms(20), ms(20), out);
  EXPECT_EQ(stamps_ms(out), (std::vector<std::int64_t>{15, 20, 25}));
}

TEST(ImuBuffer, SamplesBetweenAtTheEdgesOfWhatIsHeld) {
  const ImuBuffer buf = filled();
  std::vector<ImuSample> out;
  // Before the oldest: no lower bracket, not covered at the start.
  ImuRange r = buf.samples_between(ms(-10), ms(7), out);
  EXPECT_EQ(stamps_ms(out), (std::vector<std::int64_t>{0, 5, 10}));
  EXPECT_FALSE(r.has_before);
  EXPECT_TRUE(r.has_after);
  EXPECT_FALSE(r.covers_begin);
  EXPECT_TRUE(r.covers_end);
  // Past the newest: no upper bracket, not covered at the end.
  r = buf.samples_between(ms(42), ms(60), out);
  EXPECT_EQ(stamps_ms(out), (std::vector<std::int64_t>{40, 45, 50}));
  EXPECT_TRUE(r.has_before);
  EXPECT_FALSE(r.has_after);
  EXPECT_TRUE(r.covers_begin);
  EXPECT_FALSE(r.covers_end);
  // Entirely after: just the newest as the lower bracket.
  r = buf.samples_between(ms(70), ms(80), out);
  EXPECT_EQ(stamps_ms(out), (std::vector<std::int64_t>{50}));
  // Reversed interval: nothing, and `out` is cleared.
  r = buf.samples_between(ms(30), ms(20), out);
  EXPECT_EQ(r.count, 0u);
  EXPECT_TRUE(out.empty());
}

TEST(ImuBuffer, InterpolatesLinearlyAndExactlyOnSamples) {
  const ImuBuffer buf = filled();
  const auto on = buf.interpolate(ms(20));
  ASSERT_TRUE(on.has_value());
  EXPECT_EQ(on->angular_velocity_radps, sample_at(20, 20.0).angular_velocity_radps);
  EXPECT_EQ(on->specific_force_mps2, sample_at(20, 20.0).specific_force_mps2);

  const auto mid = buf.interpolate(ms(22));  // 2/5 of the way from 20 to 25
  ASSERT_TRUE(mid.has_value());
  const ImuSample expected = sample_at(22, 22.0);  // the values are linear in time
  EXPECT_EQ(mid->stamp, ms(22));
  EXPECT_EQ(mid->device_stamp, expected.device_stamp);
  EXPECT_NEAR((mid->angular_velocity_radps - expected.angular_velocity_radps).norm(), 0.0, 1e-12);
  EXPECT_NEAR((mid->specific_force_mps2 - expected.specific_force_mps2).norm(), 0.0, 1e-12);

  EXPECT_TRUE(buf.interpolate(ms(0)).has_value());
  EXPECT_TRUE(buf.interpolate(ms(50)).has_value());
  EXPECT_FALSE(buf.interpolate(HostTime::from_ns(-1)).has_value());
  EXPECT_FALSE(buf.interpolate(HostTime::from_ns(ms(50).ns + 1)).has_value());
}

TEST(ImuBuffer, DiscardBeforeKeepsTheLowerBracket) {
  ImuBuffer buf = filled();
  EXPECT_EQ(buf.discard_before(ms(22)), 4u);  // 0, 5, 10, 15 go; 20 stays as the bracket
  EXPECT_EQ(buf.oldest_stamp(), ms(20));
  EXPECT_EQ(buf.counters().discarded, 4u);
  EXPECT_TRUE(buf.interpolate(ms(22)).has_value());
  std::vector<ImuSample> out;
  EXPECT_TRUE(buf.samples_between(ms(22), ms(30), out).has_before);
  // On a sample stamp: the sample before it is still the bracket.
  EXPECT_EQ(buf.discard_before(ms(25)), 0u);
  EXPECT_EQ(buf.discard_before(ms(30)), 1u);
  EXPECT_EQ(buf.oldest_stamp(), ms(25));
  // Nothing older: nothing removed.
  EXPECT_EQ(buf.discard_before(ms(0)), 0u);
}

}  // namespace
}  // namespace posed
