// Pacer: the absolute schedule (due times from log times, scaled by the rate) and a sleep that
// returns at once for a past due time and gives up when told to stop. No wall-clock timing is
// asserted here; lateness is measured by posectl replay itself.

#include "tools/hil/pacer.hpp"

#include <gtest/gtest.h>

#include "drivers/common/host_clock.hpp"

namespace posed::hil {
namespace pacer_test {

TEST(Pacer, DueTimesFollowTheLogTimesFromTheAnchor) {
  Pacer p(1.0);
  p.anchor(HostTime::from_ns(5'000'000'000), 1'000'000'000'000);
  EXPECT_EQ(p.due(1'000'000'000'000).ns, 5'000'000'000);
  EXPECT_EQ(p.due(1'000'000'000'001).ns, 5'000'000'001);  // exact to the nanosecond at rate 1
  // Three hours in: still exact, nothing accumulated.
  EXPECT_EQ(p.due(1'000'000'000'000 + 10'800'000'000'000).ns, 5'000'000'000 + 10'800'000'000'000);
}

TEST(Pacer, TheRateScalesTheGapsNotTheAnchor) {
  Pacer p(2.0);
  p.anchor(HostTime::from_ns(100), 1'000);
  EXPECT_EQ(p.due(1'000).ns, 100);
  EXPECT_EQ(p.due(3'000).ns, 1'100);
  Pacer slow(0.5);
  slow.anchor(HostTime::from_ns(0), 0);
  EXPECT_EQ(slow.due(1'000'000).ns, 2'000'000);
}

TEST(Pacer, SleepUntilAPastInstantReturnsTrue) {
  std::atomic<bool> stop{false};
  EXPECT_TRUE(Pacer::sleep_until(drivers::host_now() - Duration::from_s(1), stop));
}

TEST(Pacer, SleepUntilGivesUpWhenStopped) {
  std::atomic<bool> stop{true};
  // An hour away: returns only because of the stop flag.
  EXPECT_FALSE(Pacer::sleep_until(drivers::host_now() + Duration::from_s(3600), stop));
}

}  // namespace pacer_test
}  // namespace posed::hil
