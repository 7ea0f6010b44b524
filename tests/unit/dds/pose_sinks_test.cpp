// rt/posed/pose's stamps only increase (daemon/pose_sinks). Until the back end's first optimised
// state, its IMU propagation goes out on pose; the first scan can end a fraction of a millisecond
// before the IMU sample that propagation was stamped with (room seed 33: 0.145 ms), and sending it
// then would put a pose out of order, which a TUM export (and any consumer that needs time order)
// cannot take.

#include "daemon/pose_sinks.hpp"

#include <gtest/gtest.h>

#include "daemon/config/posed_config.hpp"

namespace posed {
namespace {

NavState state_at(std::int64_t stamp_ns, bool optimised) {
  NavState s;
  s.stamp = HostTime::from_ns(stamp_ns);
  s.optimised = optimised;
  return s;
}

TEST(PoseSinks, LeavesOffPoseAnOptimisedStateStampedBeforeThePropagationAlreadySent) {
  const config::PosedConfig config;
  PoseSinks sinks(config, nullptr, nullptr, HostToWall{Duration::from_ns(0)}, HostTime::from_ns(0),
                  false);
  sinks.state(state_at(1'027'275'528, false));  // the aligned IMU's propagation: on pose
  EXPECT_EQ(sinks.tally().last_pose_stamp, HostTime::from_ns(1'027'275'528));
  sinks.state(state_at(1'027'130'784, true));  // the first scan's state, 0.145 ms older
  EXPECT_EQ(sinks.tally().pose_out_of_order, 1u);
  EXPECT_EQ(sinks.tally().last_pose_stamp, HostTime::from_ns(1'027'275'528));
  sinks.state(state_at(1'127'106'600, true));  // the next scan's
  EXPECT_EQ(sinks.tally().pose_out_of_order, 1u);
  EXPECT_EQ(sinks.tally().last_pose_stamp, HostTime::from_ns(1'127'106'600));
  // A new --loop pass starts its stamps afresh.
  sinks.new_pass();
  sinks.state(state_at(1'000'000'000, true));
  EXPECT_EQ(sinks.tally().pose_out_of_order, 1u);
  EXPECT_EQ(sinks.tally().last_pose_stamp, HostTime::from_ns(1'000'000'000));
}

}  // namespace
}  // namespace posed
