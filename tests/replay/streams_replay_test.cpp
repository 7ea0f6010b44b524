// posed --replay FILE --streams LIST replays only the recorded streams named: the rest are listed
// as left out and never read (a lidar + IMU recording replayed with --streams imu runs the IMU
// alone); a stream the recording lacks, or a list without the IMU, is refused before anything
// runs, naming what the recording has.

#include <gtest/gtest.h>

#include <chrono>

#include "daemon/pipeline/replay_sources.hpp"
#include "tests/integration/hil_helpers.hpp"
#include "tests/integration/posed_process.hpp"
#include "tests/integration/simulated_recording.hpp"

namespace posed::testing {
namespace streams_replay_test {

using namespace std::chrono_literals;

TEST(StreamsReplay, OnlyTheNamedStreamsAreReplayedAndAMissingOneIsRefused) {
  TempDir dir;
  const std::string recording = dir.file("street.mcap");
  ASSERT_TRUE(simulate_recording(dir, recording, "street_night", 4, 5, {"--no-cameras"}).ok);
  pipeline::ReplayOptions options;
  options.path = recording;
  std::string error;
  {
    const pipeline::ReplaySources all = pipeline::make_replay_sources(options, error);
    ASSERT_TRUE(all.built.sources.imu) << error;
    EXPECT_TRUE(all.built.sources.lidar);
  }
  options.only_streams = {"imu"};
  {
    const pipeline::ReplaySources imu = pipeline::make_replay_sources(options, error);
    ASSERT_TRUE(imu.built.sources.imu) << error;
    EXPECT_FALSE(imu.built.sources.lidar);
    EXPECT_NE(imu.streams.find("lidar (left out by --streams)"), std::string::npos) << imu.streams;
  }
  options.only_streams = {"imu", "visible"};
  {
    const pipeline::ReplaySources r = pipeline::make_replay_sources(options, error);
    EXPECT_FALSE(r.built.sources.imu);
    EXPECT_NE(error.find("--streams names visible, which the recording does not have (imu, lidar)"),
              std::string::npos)
        << error;
  }
  options.only_streams = {"lidar"};
  error.clear();
  EXPECT_FALSE(pipeline::make_replay_sources(options, error).built.sources.imu);
  EXPECT_NE(error.find("must include imu"), std::string::npos) << error;

  // As a user runs it: the IMU alone, the lidar listed as left out.
  const std::string config = dir.write("posed.yaml", hil_helpers::dds_config());
  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording,
                      "--max-speed", "--streams", "imu", "--wait-subscribers", "0"},
                     {}, dir);
  ASSERT_EQ(posed.wait_for_exit(120s), 0) << posed.err();
  EXPECT_NE(posed.out().find("lidar (left out by --streams)"), std::string::npos) << posed.out();
  EXPECT_NE(posed.out().find("estimator           strapdown"), std::string::npos)
      << "the IMU alone should give dead reckoning:\n"
      << posed.out();
}

}  // namespace streams_replay_test
}  // namespace posed::testing
