// The daemon's stamps follow the wall clock through its steps (an NTP correction), and a steady
// clock read with jitter never moves them.

#include "daemon/wall_clock_follower.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace posed {
namespace {

TEST(WallClockFollower, AdoptsAStepAndIgnoresJitterBelowTheTolerance) {
  std::int64_t offset_ns = 1'700'000'000'000'000'000;
  WallClockFollower follower([&] { return Duration{offset_ns}; });
  const HostToWall to_wall = follower.to_wall();
  const HostTime t = HostTime::from_ns(5'000'000'000);
  EXPECT_EQ(to_wall(t).ns, t.ns + 1'700'000'000'000'000'000);

  offset_ns += 300'000;  // 0.3 ms: jitter, or a slew between two reads
  EXPECT_FALSE(follower.poll());
  EXPECT_EQ(to_wall(t).ns, t.ns + 1'700'000'000'000'000'000);

  offset_ns += Duration::from_s(30).ns;  // the wall clock steps forward by 30 s
  const auto step = follower.poll();
  ASSERT_TRUE(step);
  EXPECT_EQ(step->ns, Duration::from_s(30).ns + 300'000);
  EXPECT_EQ(to_wall(t).ns, t.ns + offset_ns) << "a copy made before the step follows it";
  EXPECT_EQ(to_wall.to_host(to_wall(t)).ns, t.ns);
  EXPECT_EQ(to_wall.wall_minus_host.ns, 1'700'000'000'000'000'000) << "the offset at the start";

  offset_ns -= Duration::from_s(45).ns;  // and back
  ASSERT_TRUE(follower.poll());
  EXPECT_EQ(to_wall(t).ns, t.ns + offset_ns);
  EXPECT_EQ(follower.steps(), 2u);
}

TEST(WallClockFollower, TheMachinesClocksDoNotStepBetweenReads) {
  WallClockFollower follower(read_wall_minus_host);
  for (int i = 0; i < 20; ++i) {
    EXPECT_FALSE(follower.poll()) << "read " << i;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

TEST(HostToWall, AFixedOffsetConvertsBothWays) {
  const HostToWall to_wall{Duration::from_s(100)};
  EXPECT_EQ(to_wall(HostTime::from_ns(7)).ns, 100'000'000'007);
  EXPECT_EQ(to_wall.to_host(WallTime::from_ns(100'000'000'007)).ns, 7);
}

}  // namespace
}  // namespace posed
