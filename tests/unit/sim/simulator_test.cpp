// The whole simulator: deterministic for a seed (same bytes), different for another seed, every
// stream at its rate, host times in order, ground truth on the host time base.

#include "tools/sim/simulator.hpp"

#include <gtest/gtest.h>

#include <set>

#include "drivers/recording/raw_channels.hpp"
#include "tools/sim/scenarios.hpp"

namespace posed::sim {
namespace {

SimRig rig() {
  SimRig r;
  r.T_imu_lidar.translation() = Eigen::Vector3d(0.27255, -0.00053, 0.17954);
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  r.T_imu_cam.linear() = R;
  r.T_imu_cam.translation() = Eigen::Vector3d(0.57711, 0.00012, 0.83330);
  r.T_cam_thermal.translation() = Eigen::Vector3d(-0.17, 0, 0);
  r.thermal = {640, 512, 435.84, 435.91, 324.45, 255.55, -0.436, 0.166, 0, 0};
  r.visible = {640, 480, 617.97, 616.45, 327.71, 253.98, 0.148, -0.218, 0, 0};
  return r;
}

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
