// Odometry apart from the back end, live: it never waits for a stalled back end, and takes each
// anchor as soon as it arrives. (Max-speed replays make it in data order on the fusion thread;
// lio_replay_test checks that their odometry is bit-identical across runs.)

#include "daemon/pipeline/odometry_path.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace posed::pipeline {
namespace {

ImuSample still_sample(int i) {
  ImuSample s;
  s.stamp = HostTime::from_ns(1'000'000'000 + std::int64_t{i} * 5'000'000);
  s.specific_force_mps2 = Eigen::Vector3d(0, 0, 9.805);
  return s;
}

/// Every 20th sample releases an anchor 40 ms older than it, at a position that says which one
/// it is, so the odometry shows exactly which anchors it had.
NavState anchor_for(int i) {
  NavState a;
  a.stamp = still_sample(i).stamp - Duration::from_ms(40);
  a.p_map_base_m = Eigen::Vector3d(0.01 * i, 0, 0);
  a.anchor = true;
  a.optimised = true;
  return a;
}

TEST(OdometryPath, LiveOdometryNeverWaitsForAStalledBackEnd) {
  SpscQueue<AnchorItem> anchors(256, DropPolicy::kDropOldest, std::chrono::seconds(1));
  std::vector<NavState> out;
  estimator::OdometryPropagatorConfig c;
  c.blend_s = 0;  // each anchor shows at once
  OdometryPath path(c, anchors, [&](const NavState& s) { out.push_back(s); });
  anchors.push(AnchorItem{anchor_for(-20)});  // the aligned start; then the back end is stuck
  for (int i = 0; i < 200; ++i) {
    const ImuSample s = still_sample(i);
    path.on_imu(s, s.stamp - Duration::from_us(300));
  }
  // Every sample gave odometry, from the one anchor there was, stamped at the sample and
  // carrying its receive time.
  ASSERT_EQ(out.size(), 200u);
  EXPECT_EQ(out.back().stamp, still_sample(199).stamp);
  EXPECT_EQ(out.back().received, still_sample(199).stamp - Duration::from_us(300));
  EXPECT_NEAR(out.back().p_map_base_m.x(), anchor_for(-20).p_map_base_m.x(), 1e-9);
  // The back end catches up: its anchor is taken by the very next sample.
  anchors.push(AnchorItem{anchor_for(190)});
  const ImuSample next = still_sample(200);
  path.on_imu(next, next.stamp);
  EXPECT_EQ(path.figures().anchors, 2u);
  EXPECT_NEAR(out.back().p_map_base_m.x(), anchor_for(190).p_map_base_m.x(), 1e-9);
}

}  // namespace
}  // namespace posed::pipeline
