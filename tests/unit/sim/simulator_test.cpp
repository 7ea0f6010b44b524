// The whole simulator: deterministic for a seed (same bytes), different for another seed, every
// stream at its rate, host times in order, ground truth on the host time base.

#include "tools/sim/simulator.hpp"

#include <gtest/gtest.h>

#include <set>

#include "daemon/config/config_loader.hpp"
#include "drivers/camera/d4xx_metadata.hpp"
#include "drivers/common/wire_format.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "tools/sim/rig_config.hpp"
#include "tools/sim/scenarios.hpp"

namespace posed::sim {
namespace {

/// The M2DGR rig: the schema's defaults are config/posed.yaml's values.
SimRig rig() { return rig_from_config(config::default_config()); }

TEST(Simulator, SameSeedSameBytesOtherSeedOtherWorld) {
  SimOptions o;
  o.scenario = "room";
  o.duration_s = 1.5;
  o.seed = 3;
  std::string error;
  HashSink a, b, c;
  SimSummary sa, sb, sc;
  ASSERT_TRUE(run_simulation(rig(), o, a, sa, error)) << error;
  ASSERT_TRUE(run_simulation(rig(), o, b, sb, error)) << error;
  o.seed = 4;
  ASSERT_TRUE(run_simulation(rig(), o, c, sc, error)) << error;
  EXPECT_EQ(a.hash(), b.hash());
  EXPECT_NE(a.hash(), c.hash());
  EXPECT_GT(a.bytes(), 1'000'000u);
  // Other seed: other room and drive.
  std::string e;
  auto w3 = make_scenario("street_night", 3, 10, 9.805, e);
  auto w4 = make_scenario("street_night", 4, 10, 9.805, e);
  ASSERT_TRUE(w3 && w4);
  EXPECT_NE(w3->trajectory.path().length(), w4->trajectory.path().length());
  EXPECT_NE(w3->world.boxes[1].center_m, w4->world.boxes[1].center_m);
}

TEST(Simulator, StreamsRatesOrderAndGroundTruth) {
  SimOptions o;
  o.scenario = "corridor";
  o.duration_s = 2.0;
  o.seed = 9;
  MemorySink sink;
  SimSummary sum;
  std::string error;
  ASSERT_TRUE(run_simulation(rig(), o, sink, sum, error)) << error;
  namespace raw = drivers::recording::raw;
  const int imu = sink.find("imu"), lidar = sink.find("lidar"), pos = sink.find("lidar", 1);
  const int vis = sink.find("visible"), th = sink.find("thermal");
  ASSERT_TRUE(imu >= 0 && lidar >= 0 && pos >= 0 && vis >= 0 && th >= 0);
  EXPECT_EQ(sink.streams[static_cast<std::size_t>(imu)].wire_format, raw::kWireA9Serial);
  EXPECT_EQ(sink.streams[static_cast<std::size_t>(lidar)].wire_format, raw::kWireVelodyneData);
  EXPECT_EQ(sink.streams[static_cast<std::size_t>(pos)].wire_format, raw::kWireVelodynePosition);
  std::map<int, int> count;
  std::map<int, std::size_t> size;
  std::int64_t last = INT64_MIN;
  for (const auto& m : sink.messages) {
    ASSERT_GE(m.host_time.ns, last);
    last = m.host_time.ns;
    ++count[m.stream];
    size[m.stream] = m.bytes.size();
  }
  EXPECT_NEAR(count[imu], 300, 3);
  EXPECT_NEAR(count[lidar], 3014, 4);
  EXPECT_NEAR(count[pos], 2, 1);
  EXPECT_NEAR(count[vis], 30, 2);
  EXPECT_NEAR(count[th], 50, 2);
  EXPECT_EQ(size[lidar], 1206u);
  EXPECT_EQ(size[pos], 512u);
  EXPECT_EQ(size[imu], 49u);
  EXPECT_EQ(size[vis], 640u * 480u * 2u);
  EXPECT_EQ(size[th], 640u * 512u);
  ASSERT_EQ(sink.poses.size(), 200u);
  EXPECT_EQ(sink.poses[0].stamp.ns, o.host_epoch_ns);
  EXPECT_EQ(sink.poses[1].stamp.ns, o.host_epoch_ns + 10'000'000);
  // A dark corridor: the visible image is dark on average but not black.
  const auto& frame =
      std::find_if(sink.messages.rbegin(), sink.messages.rend(), [&](const auto& m) {
        return m.stream == vis;
      })->bytes;
  double mean_y = 0;
  for (std::size_t i = 0; i < frame.size(); i += 2) mean_y += static_cast<double>(frame[i]);
  mean_y /= static_cast<double>(frame.size() / 2);
  EXPECT_GT(mean_y, 8.0);
  EXPECT_LT(mean_y, 200.0);
}

TEST(Simulator, DepthAndRawThermalStreams) {
  SimRig r = rig();
  r.thermal_format = ThermalFormat::kY16;
  SimOptions o;
  o.scenario = "room";
  o.duration_s = 2.0;
  o.seed = 6;
  o.depth_camera = true;
  MemorySink sink;
  SimSummary sum;
  std::string error;
  ASSERT_TRUE(run_simulation(r, o, sink, sum, error)) << error;
  const int th = sink.find("thermal"), depth = sink.find("depth"), meta = sink.find("depth", 1);
  ASSERT_TRUE(th >= 0 && depth >= 0 && meta >= 0);
  EXPECT_EQ(sink.streams[static_cast<std::size_t>(th)].wire_format, "y16");
  EXPECT_EQ(sink.streams[static_cast<std::size_t>(depth)].wire_format, "z16");
  EXPECT_EQ(sink.streams[static_cast<std::size_t>(meta)].wire_format, drivers::wire::kUvcMetaD4xx);
  EXPECT_EQ(sink.streams[static_cast<std::size_t>(depth)].metadata.at("depth_unit_m"), "0.001");
  int frames = 0, thermal = 0;
  std::uint32_t expected_counter = 0;
  for (std::size_t i = 0; i < sink.messages.size(); ++i) {
    const auto& m = sink.messages[i];
    if (m.stream == th) {
      EXPECT_EQ(m.bytes.size(), 640u * 512u * 2u);
      ++thermal;
    }
    if (m.stream != meta) continue;
    // Each depth frame is preceded by its metadata, delivered with it.
    ASSERT_LT(i + 1, sink.messages.size());
    const auto& frame = sink.messages[i + 1];
    EXPECT_EQ(frame.stream, depth);
    EXPECT_EQ(frame.host_time.ns, m.host_time.ns);
    EXPECT_EQ(frame.bytes.size(), 640u * 480u * 2u);
    drivers::camera::D4xxFrameMetadata md;
    ASSERT_EQ(drivers::camera::parse_d4xx_metadata(m.bytes, md),
              drivers::camera::MetadataStatus::kOk);
    EXPECT_EQ(md.frame_counter, expected_counter++);
    EXPECT_EQ(md.laser_power, 150u);
    ++frames;
  }
  EXPECT_NEAR(frames, 30, 2);  // 15 Hz
  EXPECT_EQ(static_cast<std::uint64_t>(frames), sum.depth_frames);
  EXPECT_NEAR(thermal, 50, 2);
}

TEST(Simulator, NewStreamsAreDeterministicAndLeaveTheOthersAlone) {
  SimRig r = rig();
  SimOptions o;
  o.scenario = "corridor";
  o.duration_s = 1.2;
  o.seed = 8;
  std::string error;
  SimSummary sum;
  MemorySink plain;
  ASSERT_TRUE(run_simulation(r, o, plain, sum, error)) << error;
  r.thermal_format = ThermalFormat::kY16;
  o.depth_camera = true;
  HashSink a, b;
  MemorySink full;
  ASSERT_TRUE(run_simulation(r, o, a, sum, error)) << error;
  ASSERT_TRUE(run_simulation(r, o, b, sum, error)) << error;
  ASSERT_TRUE(run_simulation(r, o, full, sum, error)) << error;
  EXPECT_EQ(a.hash(), b.hash());
  o.seed = 9;
  HashSink c;
  ASSERT_TRUE(run_simulation(r, o, c, sum, error)) << error;
  EXPECT_NE(a.hash(), c.hash());
  // Turning depth on and thermal to y16 changes neither the lidar, IMU nor colour bytes.
  for (const char* name : {"imu", "lidar", "visible"}) {
    std::vector<std::vector<std::byte>> before, after;
    for (const auto& m : plain.messages)
      if (m.stream == plain.find(name)) before.push_back(m.bytes);
    for (const auto& m : full.messages)
      if (m.stream == full.find(name)) after.push_back(m.bytes);
    EXPECT_FALSE(before.empty()) << name;
    EXPECT_EQ(before, after) << name;
  }
}

TEST(Simulator, RejectsUnknownScenario) {
  SimOptions o;
  o.scenario = "moon";
  HashSink sink;
  SimSummary sum;
  std::string error;
  EXPECT_FALSE(run_simulation(rig(), o, sink, sum, error));
  EXPECT_NE(error.find("moon"), std::string::npos);
}

}  // namespace
}  // namespace posed::sim
