// Loop closure end to end, as a user runs it: `posectl sim` drives laps of a room, `posed --replay
// --max-speed --record` runs them through the mapping stage twice with loop closure and once
// without. The loops must close, the two replays with them be bit-identical (the mapping thread's
// corrections are applied in data order), odometry must not change (loops move map -> odom only),
// and the map-frame poses must differ from the odometry once a loop closed.

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "tests/integration/posed_process.hpp"
#include "tests/integration/simulated_recording.hpp"
#include "tests/replay/recorded_poses.hpp"

namespace posed::testing {
namespace loop_closure_replay_test {

using namespace std::chrono_literals;

int test_domain() { return 1 + static_cast<int>((::getpid() + 61) % 99); }

/// The number after `label` in posed's summary; -1 when absent.
long long number_after(const std::string& out, const std::string& label) {
  const auto at = out.find(label);
  if (at == std::string::npos) return -1;
  return std::stoll(out.substr(at + label.size()));
}

TEST(LoopClosureReplay, ARoomsLapsCloseLoopsIdenticallyOnEveryReplayAndLeaveOdometryAlone) {
  TempDir dir;
  const std::string recording = dir.file("room.mcap");
  ASSERT_TRUE(simulate_recording(dir, recording, "room", 50, 3, {"--no-cameras"}, 180s).ok);
  const std::string dds = loopback_dds_yaml(test_domain());
  // The room's lap is shorter than the shipped 30 s separation.
  const std::string with_loops =
      dir.write("loops.yaml", dds + "mapping:\n  loop_closure: true\n  min_separation_s: 12\n");
  const std::string without_loops =
      dir.write("odometry.yaml", dds + "mapping:\n  loop_closure: false\n");
  std::vector<std::string> summaries;
  for (const auto& [config, name] :
       {std::pair{with_loops, "a.mcap"}, {with_loops, "b.mcap"}, {without_loops, "off.mcap"}}) {
    PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording,
                        "--max-speed", "--wait-subscribers", "0", "--record", dir.file(name)},
                       {}, dir);
    ASSERT_EQ(posed.wait_for_exit(180s), 0) << posed.err();
    summaries.push_back(posed.out());
  }
  const long long loops = number_after(summaries[0], "  loops               ");
  EXPECT_GT(loops, 0) << summaries[0];
  EXPECT_EQ(number_after(summaries[1], "  loops               "), loops);
  EXPECT_EQ(summaries[2].find("  loops "), std::string::npos) << "loop closure was off";

  const auto a = recorded_poses(dir.file("a.mcap"), "/posed/pose", false);
  const auto b = recorded_poses(dir.file("b.mcap"), "/posed/pose", false);
  const auto off = recorded_poses(dir.file("off.mcap"), "/posed/pose", false);
  ASSERT_GT(a.size(), 300u);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), off.size());
  std::size_t moved = 0;
  for (auto ia = a.begin(), ib = b.begin(), io = off.begin(); ia != a.end(); ++ia, ++ib, ++io) {
    ASSERT_EQ(ia->first, ib->first);
    ASSERT_EQ(ia->second.p_xyz_m, ib->second.p_xyz_m);
    ASSERT_EQ(ia->second.q_xyzw, ib->second.q_xyzw);
    if (ia->second.p_xyz_m != io->second.p_xyz_m) ++moved;
  }
  EXPECT_GT(moved, 0u) << "the loops moved no pose into another map frame";

  // The optimised keyframes go into the recording at the end, the same on both replays.
  const auto keyframes_a = recorded_poses(dir.file("a.mcap"), "/posed/keyframes", false);
  const auto keyframes_b = recorded_poses(dir.file("b.mcap"), "/posed/keyframes", false);
  EXPECT_GT(keyframes_a.size(), 20u);
  ASSERT_EQ(keyframes_a.size(), keyframes_b.size());
  for (auto ia = keyframes_a.begin(), ib = keyframes_b.begin(); ia != keyframes_a.end();
       ++ia, ++ib) {
    ASSERT_EQ(ia->first, ib->first);
    ASSERT_EQ(ia->second.p_xyz_m, ib->second.p_xyz_m);
  }
  EXPECT_TRUE(recorded_poses(dir.file("off.mcap"), "/posed/keyframes", false).empty());

  // Odometry is the estimator's alone: bit-identical with and without the mapping stage.
  const auto odom_a = recorded_poses(dir.file("a.mcap"), "/posed/odom", true);
  const auto odom_off = recorded_poses(dir.file("off.mcap"), "/posed/odom", true);
  ASSERT_GT(odom_a.size(), 1000u);
  ASSERT_EQ(odom_a.size(), odom_off.size());
  for (auto ia = odom_a.begin(), io = odom_off.begin(); ia != odom_a.end(); ++ia, ++io) {
    ASSERT_EQ(ia->first, io->first);
    ASSERT_EQ(ia->second.p_xyz_m, io->second.p_xyz_m);
  }
}

}  // namespace loop_closure_replay_test
}  // namespace posed::testing
