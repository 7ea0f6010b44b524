// Localisation on a prior map end to end, as a user runs it: `posectl sim` drives a minute of the
// campus and `posed --save-map DIR` keeps its keyframe map; a second drive through the same world
// (`--drive-seed`, starting in the middle of the mapped stretch and the other way round) is
// replayed through `posed --map DIR`. It must localise within 2 s of data without being told
// where it is, and its map-frame poses must lie where the map says: each against the map keyframe
// nearest it, compared with the same relation in the two drives' ground truth. A damaged map stops
// posed at start naming the file.

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <string>

#include "tests/integration/posed_process.hpp"
#include "tests/replay/recorded_poses.hpp"
#include "tools/eval/trajectory_io.hpp"

namespace posed::testing {
namespace localisation_replay_test {

using namespace std::chrono_literals;

int test_domain() { return 1 + static_cast<int>((::getpid() + 67) % 99); }

/// A TUM pose at `stamp_ns` by interpolation (positions linearly, rotations by slerp); false
/// outside the trajectory.
bool pose_at(const eval::Trajectory& t, std::int64_t stamp_ns, Eigen::Isometry3d& T) {
  const auto it =
      std::lower_bound(t.stamps.begin(), t.stamps.end(), stamp_ns,
                       [](const eval::TrajectoryTime& s, std::int64_t ns) { return s.ns < ns; });
  if (it == t.stamps.begin() || it == t.stamps.end()) return false;
  const auto i = static_cast<std::size_t>(it - t.stamps.begin());
  const double u = static_cast<double>(stamp_ns - t.stamps[i - 1].ns) /
                   static_cast<double>(t.stamps[i].ns - t.stamps[i - 1].ns);
  const Eigen::Quaterniond q0(t.R_world_body[i - 1]), q1(t.R_world_body[i]);
  T = Eigen::Isometry3d::Identity();
  T.linear() = q0.slerp(u, q1).toRotationMatrix();
  T.translation() = (1 - u) * t.p_world_m[i - 1] + u * t.p_world_m[i];
  return true;
}

Eigen::Isometry3d pose_of(const eval::Trajectory& t, std::size_t i) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = t.R_world_body[i];
  T.translation() = t.p_world_m[i];
  return T;
}

TEST(LocalisationReplay, ASecondDriveLocalisesOnTheSavedMapWithinTwoSecondsAndStaysOnIt) {
  TempDir dir;
  const std::string config_path = source_dir() + "/config/posed.yaml";
  const auto simulate = [&](const std::string& name, const char* seconds,
                            std::vector<std::string> extra) {
    std::vector<std::string> args{simulator(),
                                  "sim",
                                  "--scenario",
                                  "campus",
                                  "--seed",
                                  "5",
                                  "--duration",
                                  seconds,
                                  "--no-cameras",
                                  "--config",
                                  config_path,
                                  "-o",
                                  dir.file(name + ".mcap"),
                                  "--gt",
                                  dir.file(name + ".tum")};
    args.insert(args.end(), extra.begin(), extra.end());
    PosedProcess sim(args, {}, dir);
    ASSERT_EQ(sim.wait_for_exit(180s), 0) << sim.err();
  };
  simulate("map_drive", "60", {});
  // Drive seed 12 of this world starts 33 s into the default drive's path (within 0.5 m).
  simulate("second_drive", "12", {"--drive-seed", "12"});

  const std::string config = dir.write("posed.yaml", loopback_dds_yaml(test_domain()));
  const std::string map_dir = dir.file("map");
  {
    PosedProcess posed(
        {build_dir() + "/daemon/posed", "--config", config, "--replay", dir.file("map_drive.mcap"),
         "--max-speed", "--wait-subscribers", "0", "--save-map", map_dir},
        {}, dir);
    ASSERT_EQ(posed.wait_for_exit(180s), 0) << posed.err();
    EXPECT_NE(posed.out().find(" keyframes, "), std::string::npos) << posed.out();
  }
  for (const char* file :
       {"map.yaml", "map.pcd", "keyframes.tum", "edges.txt", "scan_contexts.bin"}) {
    EXPECT_TRUE(std::filesystem::exists(map_dir + "/" + file)) << file;
  }

  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay",
                      dir.file("second_drive.mcap"), "--max-speed", "--wait-subscribers", "0",
                      "--map", map_dir, "--record", dir.file("localised.mcap")},
                     {}, dir);
  ASSERT_EQ(posed.wait_for_exit(180s), 0) << posed.err();
  const std::string out = posed.out();
  const std::string label = "first fix after ";
  const auto at = out.find(label);
  ASSERT_NE(at, std::string::npos) << out << posed.err();
  EXPECT_NE(out.find("localisation        localised;"), std::string::npos) << out;
  const double data_s = std::stod(out.substr(at + label.size()));
  EXPECT_LE(data_s, 2.0) << out;
  const std::string at_label = "s of data (at ";
  const auto fix_at = out.find(at_label, at);
  ASSERT_NE(fix_at, std::string::npos);
  eval::TrajectoryTime fix_stamp;
  const std::string fix_text = out.substr(fix_at + at_label.size());
  ASSERT_TRUE(eval::parse_stamp(fix_text.substr(0, fix_text.find(' ')), fix_stamp));

  // Every pose from the scan after the fix on (the fix's own scan made its state before the
  // mapping stage saw the scan), against the map keyframe nearest it.
  const eval::Trajectory keyframes = eval::read_trajectory(map_dir + "/keyframes.tum");
  const eval::Trajectory truth_map = eval::read_trajectory(dir.file("map_drive.tum"));
  const eval::Trajectory truth_drive = eval::read_trajectory(dir.file("second_drive.tum"));
  const auto poses = recorded_poses(dir.file("localised.mcap"), "/posed/pose", false);
  double sum2 = 0, worst = 0;
  std::size_t n = 0;
  for (const auto& [stamp_ns, p] : poses) {
    if (stamp_ns < fix_stamp.ns + 50'000'000) continue;
    Eigen::Isometry3d T_map_pose = Eigen::Isometry3d::Identity();
    T_map_pose.translation() = Eigen::Vector3d(p.p_xyz_m[0], p.p_xyz_m[1], p.p_xyz_m[2]);
    T_map_pose.linear() =
        Eigen::Quaterniond(p.q_xyzw[3], p.q_xyzw[0], p.q_xyzw[1], p.q_xyzw[2]).toRotationMatrix();
    std::size_t k = 0;
    for (std::size_t i = 1; i < keyframes.size(); ++i) {
      if ((keyframes.p_world_m[i] - T_map_pose.translation()).norm() <
          (keyframes.p_world_m[k] - T_map_pose.translation()).norm()) {
        k = i;
      }
    }
    Eigen::Isometry3d G_k, G_pose;
    if (!pose_at(truth_map, keyframes.stamps[k].ns, G_k) || !pose_at(truth_drive, stamp_ns, G_pose))
      continue;
    const Eigen::Vector3d estimated = (pose_of(keyframes, k).inverse() * T_map_pose).translation();
    const Eigen::Vector3d truth = (G_k.inverse() * G_pose).translation();
    const double e = (estimated - truth).norm();
    sum2 += e * e;
    worst = std::max(worst, e);
    ++n;
  }
  ASSERT_GT(n, 50u) << "localised poses";
  const double rms = std::sqrt(sum2 / static_cast<double>(n));
  std::printf(
      "localised after %.2f s of data; error against the map %.3f m RMS, %.3f m worst "
      "over %zu poses\n",
      data_s, rms, worst, n);
  EXPECT_LT(rms, 0.10);
  EXPECT_LT(worst, 0.50);

  // A damaged map stops posed at start, naming the file and where.
  std::filesystem::resize_file(map_dir + "/scan_contexts.bin", 100);
  PosedProcess damaged(
      {build_dir() + "/daemon/posed", "--config", config, "--replay", dir.file("second_drive.mcap"),
       "--max-speed", "--wait-subscribers", "0", "--map", map_dir},
      {}, dir);
  EXPECT_NE(damaged.wait_for_exit(60s), 0);
  EXPECT_NE(damaged.err().find("scan_contexts.bin: truncated in descriptor 0"), std::string::npos)
      << damaged.err();
}

}  // namespace localisation_replay_test
}  // namespace posed::testing
