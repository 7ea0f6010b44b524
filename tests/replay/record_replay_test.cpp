// posed --record on the synthetic A9, then posed --replay of that file at full speed, twice:
// the replays must write bit-identical pose records and publish those poses over DDS, and
// a recording cut short must replay up to the damage.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "daemon/dds/subscriber.hpp"
#include "drivers/recording/mcap_reader.hpp"
#include "tests/integration/posed_process.hpp"
#include "tests/replay/recorded_poses.hpp"

namespace posed::testing {
namespace {

using namespace std::chrono_literals;

// 1..99 is the integration tests' range too; +50 keeps a replay test and a daemon test of the
// same process id apart.
int test_domain() { return 1 + static_cast<int>((::getpid() + 50) % 99); }

std::string config_text() {
  return loopback_dds_yaml(test_domain()) +
         "imu:\n  source: synthetic\n"
         "synthetic_imu:\n  static_s: 1.5\n  ramp_s: 2\n"
         "estimator:\n  init_static_s: 0.5\n";
}

std::string posed() { return build_dir() + "/daemon/posed"; }

/// The /posed/pose messages of a recording, as bytes.
std::vector<std::vector<std::byte>> pose_records(const std::string& path) {
  drivers::recording::McapReader reader;
  std::string error;
  EXPECT_TRUE(reader.open(path, error)) << error;
  std::vector<std::vector<std::byte>> out;
  drivers::recording::McapMessage m;
  while (reader.next(m)) {
    if (m.channel->topic == "/posed/pose") out.emplace_back(m.data.begin(), m.data.end());
  }
  return out;
}

struct ReplayRun {
  int exit_code = -1;
  std::string out, err;
  std::vector<dds::Received<dds::PoseMessage>> poses;
};

ReplayRun replay(const TempDir& dir, const std::string& config, const std::string& recording,
                 const std::string& record_to) {
  std::string error;
  const std::array topics = {dds::Topic::kPose};
  dds::DdsConfig c;
  c.domain_id = static_cast<std::uint32_t>(test_domain());
  c.cyclonedds_xml_path = loopback_xml();
  auto reader = dds::Subscriber::create(c, topics, error);
  EXPECT_TRUE(reader) << error;
  PosedProcess p(
      // Discovery across processes can take longer than the default second on a loaded machine;
      // a reader matched late misses the first poses, and the two runs would differ in count.
      {posed(), "--config", config, "--replay", recording, "--max-speed", "--wait-subscribers",
       "20", "--record", record_to},
      {}, dir);
  ReplayRun run;
  const auto code = p.wait_for_exit(60s);
  run.exit_code = code.value_or(-2);
  // Reliable delivery: what was published arrives; give the last samples a moment.
  for (int i = 0; i < 10; ++i) {
    reader->wait(Duration::from_ms(50));
    reader->take_pose(run.poses);
  }
  run.out = p.out();
  run.err = p.err();
  return run;
}

TEST(Replay, MaxSpeedReplaysAreBitIdenticalAndMatchTheLiveRun) {
  TempDir dir;
  const std::string config = dir.write("posed.yaml", config_text());
  const std::string recording = dir.file("live.mcap");
  {
    PosedProcess live({posed(), "--config", config, "--duration", "5", "--record", recording}, {},
                      dir);
    ASSERT_EQ(live.wait_for_exit(30s), 0) << live.err();
    ASSERT_NE(live.out().find("recorded"), std::string::npos) << live.out();
  }
  const auto live_poses = pose_records(recording);
  ASSERT_GT(live_poses.size(), 20u);

  const ReplayRun a = replay(dir, config, recording, dir.file("replay_a.mcap"));
  const ReplayRun b = replay(dir, config, recording, dir.file("replay_b.mcap"));
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;

  // The recorded pose records of both replays are identical to the byte, and to the live run's:
  // the same bytes through the same decoder, clock sync and estimator give the same poses.
  const auto poses_a = pose_records(dir.file("replay_a.mcap"));
  const auto poses_b = pose_records(dir.file("replay_b.mcap"));
  EXPECT_EQ(poses_a, poses_b);
  EXPECT_EQ(poses_a, live_poses);

  // And over DDS: what a reader receives is what was recorded, bit for bit. The reader takes its
  // samples only after posed has exited, so it holds the last ones its keep-last-10 history
  // kept (and a reliable keep-last writer may overwrite a sample a slow reader has not
  // acknowledged): each run's reader is compared with the records, not with the other's.
  const auto recorded = recorded_poses(dir.file("replay_a.mcap"), "/posed/pose", false);
  ASSERT_EQ(recorded.size(), poses_a.size());
  for (const ReplayRun* run : {&a, &b}) {
    EXPECT_GE(run->poses.size(), std::min<std::size_t>(recorded.size(), 10));
    for (const auto& received : run->poses) {
      const auto it = recorded.find(received.msg.stamp.ns);
      ASSERT_NE(it, recorded.end())
          << "a pose over DDS that was not recorded, stamp " << received.msg.stamp.ns;
      const auto& p = it->second;
      EXPECT_EQ(received.msg.p_map_base_m,
                Eigen::Vector3d(p.p_xyz_m[0], p.p_xyz_m[1], p.p_xyz_m[2]));
      EXPECT_EQ(received.msg.q_map_base.coeffs(),
                Eigen::Vector4d(p.q_xyzw[0], p.q_xyzw[1], p.q_xyzw[2], p.q_xyzw[3]));
    }
  }
}

TEST(Replay, ARecordingCutShortReplaysUpToTheDamage) {
  TempDir dir;
  const std::string config = dir.write("posed.yaml", config_text());
  const std::string recording = dir.file("live.mcap");
  {
    PosedProcess live({posed(), "--config", config, "--duration", "4", "--record", recording}, {},
                      dir);
    ASSERT_EQ(live.wait_for_exit(30s), 0) << live.err();
  }
  // Power loss: the file ends in the middle of its data.
  const auto size = std::filesystem::file_size(recording);
  std::filesystem::resize_file(recording, size * 6 / 10);
  PosedProcess p({posed(), "--config", config, "--replay", recording, "--max-speed"}, {}, dir);
  const auto code = p.wait_for_exit(30s);
  ASSERT_TRUE(code.has_value());
  EXPECT_EQ(*code, 0) << p.err();
  EXPECT_NE(p.out().find("posed summary"), std::string::npos) << p.out();
  EXPECT_NE(p.out().find("final pose"), std::string::npos) << p.out();
  // Where the damage is, said once.
  EXPECT_NE(p.err().find("offset"), std::string::npos) << p.err();
}

}  // namespace
}  // namespace posed::testing
