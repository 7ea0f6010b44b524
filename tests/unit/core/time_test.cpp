#include "core/time.hpp"

#include <gtest/gtest.h>

#include <type_traits>

namespace posed {
namespace {

TEST(Time, DurationConstructorsAgree) {
  EXPECT_EQ(Duration::from_s(2).ns, 2'000'000'000);
  EXPECT_EQ(Duration::from_ms(3).ns, 3'000'000);
  EXPECT_EQ(Duration::from_us(5).ns, 5'000);
  EXPECT_EQ(Duration::from_seconds(0.0025).ns, 2'500'000);
  EXPECT_EQ(Duration::from_seconds(-0.0025).ns, -2'500'000);
  EXPECT_DOUBLE_EQ(Duration::from_ms(1500).seconds(), 1.5);
}

TEST(Time, TimePointArithmetic) {
  const HostTime t0 = HostTime::from_ns(1'000);
  const HostTime t1 = t0 + Duration::from_us(2);
  EXPECT_EQ(t1.ns, 3'000);
  EXPECT_EQ((t1 - t0).ns, 2'000);
  EXPECT_EQ((t0 - t1).ns, -2'000);
  EXPECT_LT(t0, t1);
  EXPECT_EQ(t1 - Duration::from_us(2), t0);
}

TEST(Time, ClocksAreDistinctTypes) {
  // A device stamp must go through ClockSync before it can meet a host stamp.
  static_assert(!std::is_same_v<DeviceTime, HostTime>);
  static_assert(!std::is_convertible_v<DeviceTime, HostTime>);
  static_assert(!std::is_convertible_v<HostTime, WallTime>);
  static_assert(!std::is_convertible_v<Duration, HostTime>);
  SUCCEED();
}

TEST(Time, HostToWallAppliesTheOffset) {
  const HostToWall to_wall{Duration::from_s(1'700'000'000)};
  EXPECT_EQ(to_wall(HostTime::from_ns(42)).ns, 1'700'000'000'000'000'042);
}

TEST(Time, LargeStampsKeepNanosecondResolution) {
  // Wall time in ns is ~1.8e18: still exact in int64, which a double would not be.
  const WallTime t = WallTime::from_ns(1'800'000'000'123'456'789);
  EXPECT_EQ((t + Duration::from_ns(1)).ns, 1'800'000'000'123'456'790);
}

}  // namespace
}  // namespace posed
