#include "core/sync/counter_unwrapper.hpp"

#include <gtest/gtest.h>

namespace posed {
namespace {

constexpr std::uint64_t k2p32 = std::uint64_t{1} << 32;

TEST(CounterUnwrapper, FirstSampleIsTakenAsIs) {
  auto u = CounterUnwrapper::with_bits(32, Duration::from_us(1));
  const auto r = u.unwrap(1234);
  EXPECT_TRUE(r.valid);
  EXPECT_FALSE(r.wrapped);
  EXPECT_EQ(r.stamp.ns, 1'234'000);
}

TEST(CounterUnwrapper, ThirtyTwoBitWrapContinuesMonotonically) {
  auto u = CounterUnwrapper::with_bits(32, Duration::from_us(1));
  u.unwrap(k2p32 - 10);
  const auto r = u.unwrap(5);
  EXPECT_TRUE(r.valid);
  EXPECT_TRUE(r.wrapped);
  EXPECT_EQ(r.stamp.ns, static_cast<std::int64_t>(k2p32 + 5) * 1000);
  EXPECT_EQ(u.wraps(), 1u);
  const auto next = u.unwrap(1005);
  EXPECT_FALSE(next.wrapped);
  EXPECT_EQ(next.stamp.ns - r.stamp.ns, 1'000'000);
}

TEST(CounterUnwrapper, SmallBackwardStepIsNotAWrap) {
  // An out-of-order sample or a device reset must come out as device time going backwards, for
  // ClockSync to judge; never as a spurious forward wrap.
  auto u = CounterUnwrapper::with_bits(32, Duration::from_us(1));
  u.unwrap(5'000'000);
  const auto r = u.unwrap(4'990'000);
  EXPECT_FALSE(r.wrapped);
  EXPECT_EQ(r.stamp.ns, 4'990'000'000);
  const auto reset = u.unwrap(0, Duration::from_ms(10));
  EXPECT_EQ(reset.stamp.ns, 0);
  EXPECT_EQ(u.wraps(), 0u);
}

TEST(CounterUnwrapper, HostTimeResolvesGapsLongerThanHalfAPeriod) {
  // An 8-bit counter of 1 ms ticks wraps every 256 ms; a 600 ms outage is ambiguous from the
  // raw value alone, but the host's elapsed time says how many periods passed.
  auto u = CounterUnwrapper::with_bits(8, Duration::from_ms(1));
  u.unwrap(100);
  const auto r = u.unwrap((100 + 600) % 256, Duration::from_ms(601));
  EXPECT_TRUE(r.wrapped);
  EXPECT_EQ(r.stamp.ns, Duration::from_ms(700).ns);
  EXPECT_EQ(u.wraps(), 2u);
}

TEST(CounterUnwrapper, HourRolloverOfMicrosecondsPastTheHour) {
  CounterUnwrapper u(3'600'000'000ull, Duration::from_us(1));
  u.unwrap(3'599'990'000ull);
  const auto r = u.unwrap(10'000, Duration::from_ms(20));
  EXPECT_TRUE(r.wrapped);
  EXPECT_EQ(r.stamp.ns, Duration::from_s(3600).ns + Duration::from_ms(10).ns);
  // After a ~2.2 h outage the host time picks the right hour.
  const auto later = u.unwrap(10'000, Duration::from_s(8000));
  EXPECT_EQ(later.stamp.ns, Duration::from_s(3600 * 3).ns + Duration::from_ms(10).ns);
}

TEST(CounterUnwrapper, OutOfRangeRawValuesAreCountedAndSkipped) {
  auto u = CounterUnwrapper::with_bits(16, Duration::from_us(1));
  u.unwrap(100);
  const auto bad = u.unwrap(70'000);
  EXPECT_FALSE(bad.valid);
  EXPECT_EQ(bad.stamp.ns, 100'000);
  EXPECT_EQ(u.invalid(), 1u);
  EXPECT_TRUE(u.unwrap(101).valid);

  auto unusable = CounterUnwrapper::with_bits(0, Duration::from_us(1));
  EXPECT_FALSE(unusable.unwrap(0).valid);
  CounterUnwrapper no_tick(1000, Duration::from_ns(0));
  EXPECT_FALSE(no_tick.unwrap(1).valid);
  EXPECT_EQ(no_tick.invalid(), 1u);
}

TEST(CounterUnwrapper, ResetForgetsThePeriod) {
  auto u = CounterUnwrapper::with_bits(8, Duration::from_us(1));
  u.unwrap(250);
  EXPECT_TRUE(u.unwrap(4).wrapped);
  u.reset();
  EXPECT_EQ(u.unwrap(4).stamp.ns, 4'000);
}

}  // namespace
}  // namespace posed
