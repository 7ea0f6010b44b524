// The A9 falls silent and the D435i's own IMU carries the estimate, end to end as a user runs it:
// `posectl sim --realsense-imu --fault imu_gap@5+3` writes both IMUs' raw bytes with the A9's
// missing for 3 s; `posed --replay --max-speed --record` hands over to the D435i's IMU and back,
// and the odometry and poses carry on through the gap. The same recording with
// realsense_imu.failover off loses the odometry for the gap (the control).

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "tests/integration/posed_process.hpp"
#include "tests/integration/simulated_recording.hpp"
#include "tests/replay/recorded_poses.hpp"
#include "tools/eval/umeyama.hpp"

namespace posed::testing {
namespace imu_failover_replay_test {

using namespace std::chrono_literals;
namespace rec = drivers::recording;

int test_domain() { return 1 + static_cast<int>((::getpid() + 41) % 99); }

struct Replay {
  std::string log;
  std::map<std::int64_t, rec::ros2::StampedPose> odom, poses;
};

/// `realsense_imu` holds more of that section's keys, each line indented by two spaces.
Replay replay(TempDir& dir, const std::string& recording, const std::string& name, bool failover,
              const std::string& realsense_imu = "") {
  const std::string config =
      dir.write(name + ".yaml", loopback_dds_yaml(test_domain()) + "realsense_imu:\n  failover: " +
                                    (failover ? "true" : "false") + "\n" + realsense_imu);
  const std::string out = dir.file(name + ".mcap");
  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording,
                      "--max-speed", "--wait-subscribers", "0", "--record", out},
                     {}, dir);
  EXPECT_EQ(posed.wait_for_exit(120s), 0) << posed.err();
  return {posed.err() + posed.out(), recorded_poses(out, "/posed/odom", true),
          recorded_poses(out, "/posed/pose", false)};
}

using Poses = std::map<std::int64_t, rec::ros2::StampedPose>;

/// ATE RMSE of `poses` against `truth` after the best rigid alignment (the estimate's map is not
/// the simulator's) [m].
double ate_m(const Poses& poses, const Poses& truth) {
  std::vector<Eigen::Vector3d> est, gt;
  for (const auto& [stamp, p] : poses) {
    const auto it = truth.lower_bound(stamp - 5'000'000);
    if (it == truth.end() || std::llabs(it->first - stamp) > 5'000'000) continue;
    est.emplace_back(p.p_xyz_m[0], p.p_xyz_m[1], p.p_xyz_m[2]);
    gt.emplace_back(it->second.p_xyz_m[0], it->second.p_xyz_m[1], it->second.p_xyz_m[2]);
  }
  if (est.size() < 3) return 1e9;
  const eval::Sim3 T = eval::umeyama(est, gt, false);
  double sq = 0;
  for (std::size_t i = 0; i < est.size(); ++i) sq += (T.apply(est[i]) - gt[i]).squaredNorm();
  return std::sqrt(sq / static_cast<double>(est.size()));
}

TEST(ImuFailoverReplay, TheD435iImuCarriesTheEstimateThroughAnA9GapAndHandsBack) {
  TempDir dir;
  const std::string recording = dir.file("street.mcap");
  {
    const Simulated sim =
        simulate_recording(dir, recording, "street_night", 12, 8,
                           {"--no-cameras", "--realsense-imu", "--fault", "imu_gap@5+3"});
    ASSERT_TRUE(sim.ok);
    EXPECT_NE(sim.out.find("D435i IMU"), std::string::npos) << sim.out;
  }
  const auto truth = recorded_poses(recording, "/posed/ground_truth", true);
  ASSERT_FALSE(truth.empty());
  const std::int64_t start_ns = truth.begin()->first;
  const auto seconds = [&](std::int64_t stamp) {
    return static_cast<double>(stamp - start_ns) * 1e-9;
  };
  const auto ate = [&](const Poses& poses) { return ate_m(poses, truth); };

  const Replay on = replay(dir, recording, "failover", true);
  EXPECT_NE(on.log.find("the estimate runs on the D435i's IMU"), std::string::npos) << on.log;
  EXPECT_NE(on.log.find("back on the A9"), std::string::npos) << on.log;
  EXPECT_NE(on.log.find("imu failover        1 time(s)"), std::string::npos) << on.log;
  std::size_t during = 0;
  double largest_gap_s = 0, last_s = -1;
  for (const auto& [stamp, p] : on.odom) {
    const double t = seconds(stamp);
    during += t > 5.1 && t < 7.9;
    if (t > 4 && t < 9 && last_s >= 0) largest_gap_s = std::max(largest_gap_s, t - last_s);
    last_s = t;
  }
  EXPECT_GT(during, 500u) << "odometry at the D435i gyro's 200 Hz through the A9's 3 s gap";
  EXPECT_LT(largest_gap_s, 0.06) << "the hand-over waits failover_after_s (0.05 s), no longer";
  const double ate_on = ate(on.poses);
  EXPECT_LT(ate_on, 0.10);
  RecordProperty("ate_with_failover_m", std::to_string(ate_on));

  // Deterministic: the hand-over is decided in the data's order.
  const Replay again = replay(dir, recording, "failover_again", true);
  ASSERT_EQ(again.poses.size(), on.poses.size());
  for (auto a = on.poses.begin(), b = again.poses.begin(); a != on.poses.end(); ++a, ++b) {
    ASSERT_EQ(a->first, b->first);
    for (int i = 0; i < 3; ++i) ASSERT_EQ(a->second.p_xyz_m[i], b->second.p_xyz_m[i]);
  }

  // The control: without the failover nothing propagates through the gap.
  const Replay off = replay(dir, recording, "no_failover", false);
  EXPECT_EQ(off.log.find("the estimate runs on the D435i's IMU"), std::string::npos);
  std::size_t during_off = 0;
  for (const auto& [stamp, p] : off.odom) {
    const double t = seconds(stamp);
    during_off += t > 5.1 && t < 7.9;
  }
  EXPECT_LT(during_off, 10u);
  RecordProperty("ate_without_failover_m", std::to_string(ate(off.poses)));
  std::printf("ATE with the failover %.4f m, without %.4f m\n", ate_on, ate(off.poses));
}

// With the lidar out too, the D435i's samples alone carry the odometry: weighed with its own
// noise, and with the bias state free to step to the D435i's bias where its samples begin
// (realsense_imu.*_bias_offset), it drifts less than weighed as the A9 with the A9's bias.
TEST(ImuFailoverReplay, TheD435isOwnNoiseAndBiasCarryTheOdometryWhenTheLidarIsOutToo) {
  TempDir dir;
  const std::string recording = dir.file("street.mcap");
  ASSERT_TRUE(simulate_recording(dir, recording, "street_night", 12, 9,
                                 {"--no-cameras", "--realsense-imu", "--fault", "imu_gap@5+4",
                                  "--fault", "lidar_outage@6+2"})
                  .ok);
  const auto truth = recorded_poses(recording, "/posed/ground_truth", true);
  ASSERT_FALSE(truth.empty());
  // The shipped weights against the A9's densities and no bias step (before stop 34).
  const Replay own = replay(dir, recording, "own", true);
  const Replay as_a9 = replay(dir, recording, "as_a9", true,
                              "  gyro_noise_density: 2.3417543020438883e-03\n"
                              "  gyro_random_walk: 1.4428407712885209e-05\n"
                              "  accel_noise_density: 3.7686306102624571e-02\n"
                              "  accel_random_walk: 1.1416642385952368e-03\n"
                              "  gyro_bias_offset_radps: 0\n"
                              "  accel_bias_offset_mps2: 0\n");
  ASSERT_NE(own.log.find("imu failover        1 time(s)"), std::string::npos) << own.log;
  const double odom_own = ate_m(own.odom, truth), odom_as_a9 = ate_m(as_a9.odom, truth);
  std::printf(
      "odom ATE through the A9 gap with the lidar out: own noise %.4f m, as the A9 %.4f m\n",
      odom_own, odom_as_a9);
  RecordProperty("odom_ate_own_noise_m", std::to_string(odom_own));
  RecordProperty("odom_ate_as_a9_m", std::to_string(odom_as_a9));
  EXPECT_LT(odom_own, odom_as_a9);
  EXPECT_LT(ate_m(own.poses, truth), 0.10);
}

}  // namespace imu_failover_replay_test
}  // namespace posed::testing
