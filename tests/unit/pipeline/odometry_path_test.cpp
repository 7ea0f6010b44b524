// Odometry apart from the back end: in a max-speed replay it is the same whatever the threads'
// timing; live, it never waits for a stalled back end.

#include "daemon/pipeline/odometry_path.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <thread>
#include <vector>

namespace posed::pipeline {
namespace {

constexpr int kSamples = 600;  // 3 s at 200 Hz

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

/// The back end: consumes the IMU queue, releases anchors, reports progress, with random pauses
/// (seeded) standing in for scan matches of varying length.
void back_end(SpscQueue<ImuItem>& imu, SpscQueue<AnchorItem>& anchors, BackEndProgress& progress,
              std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pause_us(0, 400);
  int consumed = 0;
  while (consumed < kSamples) {
    ImuItem item;
    if (!imu.try_pop(item)) {
      std::this_thread::yield();
      continue;
    }
    if (consumed % 20 == 19) {
      std::this_thread::sleep_for(std::chrono::microseconds(pause_us(rng)));
      anchors.push(AnchorItem{anchor_for(consumed), item.sample.stamp});
    }
    progress.consumed_imu(item.sample.stamp);
    ++consumed;
  }
  progress.ended();
}

std::vector<NavState> run(bool deterministic, std::uint64_t seed) {
  SpscQueue<ImuItem> imu(1024, DropPolicy::kBlockWithTimeout, std::chrono::seconds(5));
  SpscQueue<AnchorItem> anchors(256, DropPolicy::kBlockWithTimeout, std::chrono::seconds(5));
  BackEndProgress progress;
  std::vector<NavState> out;
  estimator::OdometryPropagatorConfig c;
  c.blend_s = 0;  // each anchor shows at once
  OdometryPath path(c, anchors, progress, deterministic,
                    [&](const NavState& s) { out.push_back(s); });
  anchors.push(AnchorItem{anchor_for(-20), HostTime::from_ns(0)});  // the aligned start
  Heartbeat heartbeat("imu_source");
  std::thread consumer([&] { back_end(imu, anchors, progress, seed); });
  std::mt19937_64 rng(seed + 100);
  std::uniform_int_distribution<int> pause_us(0, 60);
  for (int i = 0; i < kSamples; ++i) {
    const ImuSample s = still_sample(i);
    imu.push(ImuItem{s, false, {}});
    if (i % 7 == 0) std::this_thread::sleep_for(std::chrono::microseconds(pause_us(rng)));
    path.on_imu(s, s.stamp, heartbeat);
  }
  consumer.join();
  return out;
}

TEST(OdometryPath, AMaxSpeedReplayGivesTheSameOdometryWhateverTheScheduling) {
  const std::vector<NavState> a = run(true, 1);
  const std::vector<NavState> b = run(true, 2);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), static_cast<std::size_t>(kSamples));
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].stamp, b[i].stamp) << i;
    ASSERT_EQ(a[i].p_map_base_m, b[i].p_map_base_m) << i;  // bit-identical
  }
  // Sample k saw exactly the anchors released before it: the one released by sample 19 (at its
  // stamp) first shows at sample 20.
  EXPECT_DOUBLE_EQ(a[19].p_map_base_m.x(), anchor_for(-20).p_map_base_m.x());
  EXPECT_NEAR(a[20].p_map_base_m.x(), anchor_for(19).p_map_base_m.x(), 1e-9);
}

TEST(OdometryPath, LiveOdometryNeverWaitsForAStalledBackEnd) {
  SpscQueue<AnchorItem> anchors(256, DropPolicy::kDropOldest, std::chrono::seconds(1));
  BackEndProgress progress;  // never advances: the back end is stuck in a scan match
  std::vector<NavState> out;
  OdometryPath path(estimator::OdometryPropagatorConfig{}, anchors, progress, false,
                    [&](const NavState& s) { out.push_back(s); });
  anchors.push(AnchorItem{anchor_for(-20), HostTime::from_ns(0)});
  Heartbeat heartbeat("imu_source");
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 200; ++i) {
    const ImuSample s = still_sample(i);
    path.on_imu(s, s.stamp, heartbeat);
  }
  const auto took = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(out.size(), 200u);
  // Nothing waited: waiting for the back end would be a 50 ms stage wait per sample (10 s).
  EXPECT_LT(took, std::chrono::seconds(5));
  // An anchor arriving late is still taken by the next sample.
  anchors.push(AnchorItem{anchor_for(100), still_sample(100).stamp});
  const ImuSample next = still_sample(200);
  path.on_imu(next, next.stamp, heartbeat);
  EXPECT_EQ(path.figures().anchors, 2u);
}

}  // namespace
}  // namespace posed::pipeline
