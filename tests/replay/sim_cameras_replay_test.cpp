// Every camera stream the simulator writes, replayed by posed as a user runs it: `posectl sim
// --depth --thermal-format y16` records colour frames with their D4xx metadata, 16-bit raw
// thermal frames and the D435i's depth stream; `posed --replay --max-speed` decodes the colour,
// y16 thermal (y16 -> mono16) and Z16 depth frames without a malformed one, stamps the depth
// frames from their hardware clock, gives camera features the depth image's depth where the
// lidar gives none, and exits cleanly.

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <iterator>
#include <regex>
#include <string>

#include "tests/integration/posed_process.hpp"
#include "tests/integration/simulated_recording.hpp"

namespace posed::testing {
// Named rather than anonymous: test binaries build as unity batches.
namespace sim_cameras_replay_test {

using namespace std::chrono_literals;

int test_domain() { return 1 + static_cast<int>((::getpid() + 61) % 99); }

/// Occurrences of `needle` in `text`.
std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (auto at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

TEST(SimCamerasReplay, DepthAndRawThermalDecodeAndTheDepthImageGivesFeaturesDepth) {
  TempDir dir;
  const std::string recording = dir.file("cameras.mcap");
  int visible_frames = 0, thermal_frames = 0, depth_frames = 0;
  {
    const Simulated sim =
        simulate_recording(dir, recording, "room", 3, 3, {"--depth", "--thermal-format", "y16"});
    ASSERT_TRUE(sim.ok);
    const std::string out = sim.out;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        out, m,
        std::regex(R"(visible (\d+) frames; thermal (\d+) frames \(y16\); depth (\d+) frames)")))
        << out;
    visible_frames = std::stoi(m[1]);
    thermal_frames = std::stoi(m[2]);
    EXPECT_NEAR(visible_frames, 45, 2);  // 15 Hz
    EXPECT_NEAR(thermal_frames, 75, 2);  // 25 Hz
    depth_frames = std::stoi(m[3]);
    EXPECT_NEAR(depth_frames, 45, 2);
  }
  const std::string config = dir.write(
      "posed.yaml", loopback_dds_yaml(test_domain()) + "depth_camera:\n  feature_depth: true\n");
  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording,
                      "--max-speed", "--wait-subscribers", "0"},
                     {}, dir);
  ASSERT_EQ(posed.wait_for_exit(120s), 0) << posed.err();
  const std::string out = posed.out(), err = posed.err();
  EXPECT_EQ(count(err, "not replayed"), 0u) << err;
  EXPECT_EQ(count(err, "error"), 0u) << err;
  EXPECT_NE(out.find("(depth, imu, lidar, thermal, visible)"), std::string::npos) << out;
  // Every frame decoded, none malformed or dropped; colour stamped from its hardware clock.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m,
                                std::regex(R"(thermal +(\d+) decoded .*, (\d+) malformed, (\d+) )"
                                           R"(dropped; clock (\w+))")))
      << out;
  EXPECT_EQ(std::stoi(m[1]), thermal_frames);
  EXPECT_EQ(std::stoi(m[2]), 0);
  EXPECT_EQ(std::stoi(m[3]), 0);
  ASSERT_TRUE(std::regex_search(
      out, m,
      std::regex(R"(visible +(\d+) decoded .*, (\d+) malformed, (\d+) dropped; clock (\w+))")))
      << out;
  EXPECT_EQ(std::stoi(m[1]), visible_frames);
  EXPECT_EQ(std::stoi(m[2]), 0);
  EXPECT_EQ(m[4], "locked");
  ASSERT_TRUE(std::regex_search(
      out, m,
      std::regex(R"(depth +(\d+) decoded .*, (\d+) malformed, (\d+) dropped; clock (\w+))")))
      << out;
  EXPECT_EQ(std::stoi(m[1]), depth_frames);
  EXPECT_EQ(std::stoi(m[2]), 0);
  EXPECT_EQ(std::stoi(m[3]), 0);
  EXPECT_EQ(m[4], "locked");
  // The room's near walls and floor, below and between the lidar's rings: the depth image gives
  // features depth the lidar does not, on every frame after the estimator has aligned (about a
  // second of the three: before, no pose moves a depth image to a frame's stamp).
  ASSERT_TRUE(std::regex_search(
      out, m,
      std::regex(
          R"(visible: (\d+) frames .*depth-image depth for ([0-9.]+) % more \((\d+) frames)")))
      << out;
  EXPECT_GT(std::stod(m[2]), 1.0);
  EXPECT_GE(2 * std::stoi(m[3]), std::stoi(m[1]));
}

}  // namespace sim_cameras_replay_test

namespace sim_cameras_replay_test {

std::string slurp_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(SimCamerasReplay, TheSameSeedWritesTheSameFileByteForByte) {
  TempDir dir;
  std::string files[2];
  for (int i = 0; i < 2; ++i) {
    const std::string path = dir.file("run" + std::to_string(i) + ".mcap");
    const Simulated sim = simulate_recording(dir, path, "room", 2, 11, {"--depth"});
    ASSERT_TRUE(sim.ok);
    files[i] = slurp_file(path);
  }
  ASSERT_GT(files[0].size(), 10'000'000u);  // every sensor, chunked and indexed
  EXPECT_TRUE(files[0] == files[1]) << "two runs of one seed wrote different files";
}

}  // namespace sim_cameras_replay_test
}  // namespace posed::testing
