// The camera front end in a whole replay, as a user runs it: a simulated night drive with both
// cameras through posed (the summary line and determinism) and through posectl inspect frontend
// (the three modes side by side, annotated frames).

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <regex>
#include <string>

#include "tests/integration/posed_process.hpp"
#include "tests/integration/simulated_recording.hpp"

namespace posed::testing {
namespace frontend_replay_test {
namespace {

using namespace std::chrono_literals;

// A DDS domain of this test process's own, so parallel tests never meet.
int test_domain() { return 1 + static_cast<int>((::getpid() + 12) % 99); }

TEST(FrontendReplay, ANightDriveRunsTheThreeModesOnTheSameFramesAndPosedReportsTheFusedOne) {
  TempDir dir;
  const std::string recording = dir.file("night.mcap");
  const std::string posectl = build_dir() + "/tools/posectl/posectl";
  ASSERT_TRUE(simulate_recording(dir, recording, "street_night", 8, 4, {}, 180s).ok);
  const std::string frames = dir.file("frames");
  PosedProcess inspect(
      {posectl, "inspect", "frontend", recording, "--config", source_dir() + "/config/posed.yaml",
       "--save-frames", frames, "--every", "20"},
      {}, dir);
  ASSERT_EQ(inspect.wait_for_exit(180s), 0) << inspect.err() << inspect.out();
  const std::string& table = inspect.out();
  // One column per mode, every visible frame of 8 s at 15 Hz an event (a few at the start wait
  // for the IMU, the last may wait for its partner).
  ASSERT_NE(table.find("visible     thermal       fused"), std::string::npos) << table;
  std::smatch m;
  ASSERT_TRUE(
      std::regex_search(table, m, std::regex(R"(frames processed \[1\]\s+(\d+)\s+(\d+)\s+(\d+))")))
      << table;
  for (int i = 1; i <= 3; ++i) {
    EXPECT_GE(std::stoi(m[i]), 100) << table;
    EXPECT_LE(std::stoi(m[i]), 121) << table;
  }
  ASSERT_TRUE(std::regex_search(
      table, m, std::regex(R"(match success rate \[%\]\s+([\d.]+)\s+([\d.]+)\s+([\d.]+))")))
      << table;
  for (int i = 1; i <= 3; ++i) {
    EXPECT_GT(std::stod(m[i]), 20.0) << table;  // tracking works in every mode ...
    EXPECT_LE(std::stod(m[i]), 100.0) << table;
  }
  ASSERT_TRUE(std::regex_search(
      table, m,
      std::regex(R"(depth association \[% of features\]\s+([\d.]+)\s+([\d.]+)\s+([\d.]+))")))
      << table;
  for (int i = 1; i <= 3; ++i) EXPECT_GT(std::stod(m[i]), 10.0) << table;  // ... and lidar depth
  // Against the simulator's truth, the visible camera's tracks on a lit street follow the world
  // (76 % of the steps with 2 px of true motion within 1 px or 20 % of it; the simulated
  // corridor's plain, grainy walls give 12 %): the truth's rays, poses and projection agree
  // with the tracker's.
  ASSERT_TRUE(std::regex_search(
      table, m, std::regex(R"(tracks following the world \[%\]\s+([\d.]+)\s+([\d.]+)\s+([\d.]+))")))
      << table;
  EXPECT_GT(std::stod(m[1]), 50.0) << table;
  // Night: the thermal camera sees better than the visible one (seed 002's confidence), each in
  // its own mode's column.
  ASSERT_TRUE(
      std::regex_search(table, m, std::regex(R"(mean confidence, visible \[0\.\.1\]\s+([\d.]+))")))
      << table;
  const double visible_confidence = std::stod(m[1]);
  ASSERT_TRUE(std::regex_search(
      table, m, std::regex(R"(mean confidence, thermal \[0\.\.1\]\s+-\s+([\d.]+))")))
      << table;
  EXPECT_LT(visible_confidence, std::stod(m[1])) << table;
  std::size_t pngs = 0;
  for (const auto& e : std::filesystem::directory_iterator(frames)) {
    pngs += e.path().extension() == ".png" ? 1 : 0;
  }
  EXPECT_GE(pngs, 9u) << "annotated frames: three modes, several each";

  // posed itself, in seed 000's fused mode: the front end's summary line, and two replays agree
  // to the byte.
  const std::string config =
      dir.write("posed.yaml", loopback_dds_yaml(test_domain()) + "frontend:\n  mode: fused\n");
  std::string lines[2];
  for (std::string& line : lines) {
    PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording,
                        "--max-speed", "--wait-subscribers", "0"},
                       {}, dir);
    ASSERT_EQ(posed.wait_for_exit(180s), 0) << posed.err();
    const std::size_t at = posed.out().find("camera front end    fused:");
    ASSERT_NE(at, std::string::npos) << posed.out();
    line = posed.out().substr(at, posed.out().find('\n', at) - at);
  }
  EXPECT_EQ(lines[0], lines[1]);
}

}  // namespace
}  // namespace frontend_replay_test
}  // namespace posed::testing
