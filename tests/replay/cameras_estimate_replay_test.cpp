// The cameras in the estimate, end to end as a user runs it: `posectl sim` writes a short drive
// down the simulated coal-mine roadway (`tunnel`: its lidar geometry is the same along its axis,
// its shotcrete walls are textured for the colour camera), `posed --replay --max-speed --record`
// runs it with the visible camera's motion in the window, twice, and once with the cameras off.
// The lidar alone loses the axis; with the camera the poses follow the ground truth. The two
// camera replays run the camera front end on a thread of its own (the default) and on the fusion
// thread (frontend.own_thread: false), and are bit-identical: the thread changes the speed, not
// the estimate.

#include <gtest/gtest.h>
#include <unistd.h>

#include <map>
#include <regex>
#include <string>
#include <vector>

#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/ros2_messages.hpp"
#include "tests/integration/posed_process.hpp"
#include "tests/integration/simulated_recording.hpp"
#include "tests/replay/recorded_poses.hpp"
#include "tools/eval/umeyama.hpp"

namespace posed::testing {
// Named rather than anonymous: test binaries build as unity batches.
namespace cameras_estimate_replay_test {

using namespace std::chrono_literals;
namespace rec = drivers::recording;

int test_domain() { return 1 + static_cast<int>((::getpid() + 37) % 99); }

Eigen::Vector3d xyz(const rec::ros2::StampedPose& p) {
  return {p.p_xyz_m[0], p.p_xyz_m[1], p.p_xyz_m[2]};
}

/// ATE RMSE [m] of `estimate` against `truth` (matched within 5 ms) after SE(3) alignment.
double ate_m(const std::map<std::int64_t, rec::ros2::StampedPose>& estimate,
             const std::map<std::int64_t, rec::ros2::StampedPose>& truth) {
  std::vector<Eigen::Vector3d> est, gt;
  for (const auto& [stamp, p] : estimate) {
    auto it = truth.lower_bound(stamp - 5'000'000);
    if (it == truth.end() || std::llabs(it->first - stamp) > 5'000'000) continue;
    est.push_back(xyz(p));
    gt.push_back(xyz(it->second));
  }
  EXPECT_GT(est.size(), estimate.size() * 9 / 10);
  const eval::Sim3 T = eval::umeyama(est, gt, false);
  double sq = 0;
  for (std::size_t i = 0; i < est.size(); ++i) sq += (T.apply(est[i]) - gt[i]).squaredNorm();
  return std::sqrt(sq / static_cast<double>(est.size()));
}

/// The numbers `pattern`'s groups capture in a summary, in order; the test fails (and each
/// number reads -1) when the summary has no such line.
std::vector<int> numbers_in(const std::string& summary, const std::string& pattern) {
  const std::regex re(pattern);
  std::smatch m;
  if (!std::regex_search(summary, m, re)) {
    ADD_FAILURE() << "no \"" << pattern << "\" in the summary:\n" << summary;
    return std::vector<int>(re.mark_count(), -1);
  }
  std::vector<int> numbers;
  for (std::size_t i = 1; i < m.size(); ++i) numbers.push_back(std::stoi(m[i]));
  return numbers;
}

/// A simulated drive (`posectl sim`) and its ground truth.
struct Drive {
  TempDir dir;
  std::string recording = dir.file("sim.mcap");
  std::map<std::int64_t, rec::ros2::StampedPose> truth;
};

bool simulate(Drive& drive, const std::string& scenario, int seconds, int seed) {
  if (!simulate_recording(drive.dir, drive.recording, scenario, seconds, seed, {}, 300s).ok) {
    return false;
  }
  drive.truth = recorded_poses(drive.recording, "/posed/ground_truth", true);
  return true;
}

struct Replay {
  std::map<std::int64_t, rec::ros2::StampedPose> poses;
  std::string summary;
};

Replay replay(TempDir& dir, const std::string& recording, const std::string& mode,
              const std::string& name, bool own_thread = true, const std::string& extra_yaml = "") {
  const std::string config = dir.write(
      name + ".yaml", loopback_dds_yaml(test_domain()) + "frontend:\n  mode: " + mode +
                          "\n  own_thread: " + (own_thread ? "true" : "false") + "\n" + extra_yaml);
  PosedProcess posed(
      {build_dir() + "/daemon/posed", "--config", config, "--replay", recording, "--max-speed",
       "--wait-subscribers", "0", "--record", dir.file(name + ".mcap")},
      {}, dir);
  EXPECT_EQ(posed.wait_for_exit(300s), 0) << posed.err();
  return {recorded_poses(dir.file(name + ".mcap"), "/posed/pose", false), posed.out()};
}

TEST(CamerasEstimateReplay, TheVisibleCameraHoldsATunnelTheLidarLoses) {
  Drive drive;
  ASSERT_TRUE(simulate(drive, "tunnel", 30, 4));
  const Replay a = replay(drive.dir, drive.recording, "visible", "a");
  const Replay b = replay(drive.dir, drive.recording, "visible", "b", false);
  const Replay lio = replay(drive.dir, drive.recording, "off", "lio");
  ASSERT_GT(a.poses.size(), 250u);  // 10 Hz after the 2 s standing start

  // The camera is in the estimate, and says so.
  EXPECT_NE(a.summary.find("visible motion in the window"), std::string::npos) << a.summary;
  EXPECT_GT(numbers_in(a.summary, R"(visible +factors +(\d+) between)")[0], 200);
  EXPECT_NE(a.summary.find("imu+lidar+visible"), std::string::npos) << a.summary;
  EXPECT_NE(a.summary.find("camera front end on a thread of its own"), std::string::npos)
      << a.summary;
  EXPECT_EQ(b.summary.find("on a thread of its own"), std::string::npos) << b.summary;

  // Bit-identical replays with the camera in the estimate, its front end threaded or not.
  ASSERT_EQ(a.poses.size(), b.poses.size());
  for (auto ia = a.poses.begin(), ib = b.poses.begin(); ia != a.poses.end(); ++ia, ++ib) {
    ASSERT_EQ(ia->first, ib->first);
    ASSERT_EQ(ia->second.p_xyz_m, ib->second.p_xyz_m);
    ASSERT_EQ(ia->second.q_xyzw, ib->second.q_xyzw);
  }

  const double with_camera = ate_m(a.poses, drive.truth);
  const double lidar_only = ate_m(lio.poses, drive.truth);
  std::printf("tunnel seed 4, 30 s: ATE %.3f m with the visible camera, %.3f m lidar-inertial\n",
              with_camera, lidar_only);
  // Measured when written: 0.49 m against 4.96 m; 0.115 m since features that hold still are
  // left out (stop 28). The camera must cut the error tenfold and keep it under 0.3 m in 30 s,
  // which the lidar alone cannot.
  EXPECT_LT(with_camera, 0.3);
  EXPECT_LT(with_camera, lidar_only / 10);
  EXPECT_GT(lidar_only, 1.0);
}

TEST(CamerasEstimateReplay, ThroughTheSmokeTheImuCarriesTheAxisTheScansWouldHoldStill) {
  // A short drive down the smoke roadway: the colour camera's gate closes in the dense smoke and
  // reopens after it. While it is out, the roadway's scans would hold the axis still (they pin
  // it weakly and cannot be checked); posed leaves that axis to the IMU, which carries the speed
  // the camera measured before the smoke.
  Drive drive;
  ASSERT_TRUE(simulate(drive, "smoke", 40, 4));
  const Replay left = replay(drive.dir, drive.recording, "visible", "left");
  const Replay held = replay(drive.dir, drive.recording, "visible", "held", true,
                             "estimator:\n  camera_blind_weak_lidar_ratio: 0\n");
  ASSERT_GT(left.poses.size(), 350u);

  // The visible stream left in the smoke and came back.
  const std::vector<int> gate =
      numbers_in(left.summary, R"(visible +factors .*left (\d+), rejoined (\d+) times)");
  EXPECT_GE(gate[0], 1);
  EXPECT_GE(gate[1], 1);
  const std::string left_to_imu = R"((\d+) left to the IMU while the cameras were blind)";
  EXPECT_GT(numbers_in(left.summary, left_to_imu)[0], 20);
  EXPECT_EQ(numbers_in(held.summary, left_to_imu)[0], 0);

  const double ate_left = ate_m(left.poses, drive.truth);
  const double ate_held = ate_m(held.poses, drive.truth);
  std::printf("smoke seed 4, 40 s: ATE %.3f m with the axis left to the IMU, %.3f m held\n",
              ate_left, ate_held);
  // Measured when written: 0.144 m against 9.32 m; 0.150 m against 9.21 m with RANSAC capped at
  // 200 draws (stop 51).
  EXPECT_LT(ate_left, 0.5);
  EXPECT_GT(ate_held, 4 * ate_left);
}

}  // namespace cameras_estimate_replay_test
}  // namespace posed::testing
