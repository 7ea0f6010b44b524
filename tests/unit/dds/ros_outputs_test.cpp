// The ROS 2 tool outputs built from posed's states and status (daemon/ros_outputs): the path
// stays bounded without losing the run's extent, diagnostics map health to ROS levels, and the
// static transforms chain the camera and thermal extrinsics.

#include "daemon/ros_outputs.hpp"

#include <gtest/gtest.h>

namespace posed {
namespace {

dds::PoseMessage pose_at(double x_m) {
  dds::PoseMessage p;
  p.stamp = WallTime::from_ns(static_cast<std::int64_t>(x_m * 1e9));
  p.p_map_base_m = {x_m, 0, 0};
  return p;
}

TEST(PathBuilder, KeepsPosesAStepApartAndThinsTheOldOnesPastTheCap) {
  PathBuilder builder(0.1, 100);
  for (int i = 0; i <= 1000; ++i) builder.add(pose_at(i * 0.05));  // 50 m in 5 cm steps
  const auto& poses = builder.path().poses;
  EXPECT_LE(poses.size(), 100u);
  EXPECT_GE(poses.size(), 50u);
  // The whole run is still there, start to end, in order.
  EXPECT_EQ(poses.front().p_map_base_m.x(), 0.0);
  EXPECT_DOUBLE_EQ(poses.back().p_map_base_m.x(), 50.0);
  for (std::size_t i = 1; i + 1 < poses.size(); ++i) {  // the newest may be closer
    EXPECT_GE(poses[i].p_map_base_m.x() - poses[i - 1].p_map_base_m.x(), 0.1 - 1e-9);
  }
  EXPECT_EQ(builder.path().stamp, pose_at(50.0).stamp);
}

/// Whether `status` lists `key` with `value`.
bool has_value(const dds::DiagnosticStatusMessage& status, const std::string& key,
               const std::string& value) {
  return std::find(status.values.begin(), status.values.end(),
                   std::pair<std::string, std::string>{key, value}) != status.values.end();
}

TEST(RosDiagnostics, StreamHealthBecomesRosLevelsWithFigures) {
  pipeline::PipelineStatus st;
  st.mode = EstimatorMode::kLidarInertial;
  for (const char* health : {"ok", "degraded", "no_data", "device_lost"}) {
    pipeline::StreamStatus s;
    s.name = health;
    s.health = health;
    s.decoded = 7;
    s.clock_state = "locked";
    st.streams.push_back(s);
  }
  const dds::DiagnosticsMessage msg = diagnostics(st, WallTime::from_ns(1));
  ASSERT_EQ(msg.status.size(), 5u);
  using L = dds::DiagnosticStatusMessage;
  EXPECT_EQ(msg.status[0].level, L::kOk);
  EXPECT_EQ(msg.status[1].level, L::kWarn);
  EXPECT_EQ(msg.status[2].level, L::kStale);
  EXPECT_EQ(msg.status[3].level, L::kError);
  EXPECT_EQ(msg.status[0].name, "posed: ok");
  EXPECT_TRUE(has_value(msg.status[0], "decoded", "7"));
  EXPECT_EQ(msg.status[4].name, "posed: estimator");
  EXPECT_EQ(msg.status[4].level, L::kOk);
  st.mode = EstimatorMode::kAligning;
  EXPECT_EQ(diagnostics(st, WallTime::from_ns(1)).status[4].level, L::kWarn);
}

TEST(RosDiagnostics, TheMappingStageIsAWarningUntilLocalised) {
  pipeline::PipelineStatus st;
  using L = dds::DiagnosticStatusMessage;
  // No mapping stage: no mapping status.
  ASSERT_EQ(diagnostics(st, WallTime::from_ns(1)).status.size(), 1u);
  pipeline::MappingStatus& m = st.mapping.emplace();
  m.localising = true;
  m.state = "aligning";
  m.correction_m = 12.5;
  const dds::DiagnosticsMessage aligning = diagnostics(st, WallTime::from_ns(1));
  ASSERT_EQ(aligning.status.size(), 2u);
  const L& d = aligning.status[1];
  EXPECT_EQ(d.name, "posed: mapping");
  EXPECT_EQ(d.level, L::kWarn);
  EXPECT_EQ(d.message, "aligning");
  EXPECT_TRUE(has_value(d, "map -> odom", "12.500 m"));
  m.state = "localised";
  m.fixes = 3;
  const L localised = diagnostics(st, WallTime::from_ns(1)).status[1];
  EXPECT_EQ(localised.level, L::kOk);
  EXPECT_TRUE(has_value(localised, "fixes", "3"));
  m.state = "lost";
  EXPECT_EQ(diagnostics(st, WallTime::from_ns(1)).status[1].level, L::kWarn);
  // Closing loops is never a warning by itself.
  m.localising = false;
  m.state = "mapping";
  m.loops = 4;
  const L mapping = diagnostics(st, WallTime::from_ns(1)).status[1];
  EXPECT_EQ(mapping.level, L::kOk);
  EXPECT_TRUE(has_value(mapping, "loops", "4"));
}

TEST(RosStaticTransforms, ThermalIsTheCameraExtrinsicChainedWithCameraToThermal) {
  config::PosedConfig config;
  config.dds.base_frame = "base_link";
  config.dds.lidar_frame = "velodyne";
  config.dds.camera_frame = "cam";
  config.dds.thermal_frame = "thermal";
  const auto translation = [](double x, double y, double z) {
    return config::Transform4{1, 0, 0, x, 0, 1, 0, y, 0, 0, 1, z, 0, 0, 0, 1};
  };
  config.extrinsics.T_imu_lidar = translation(0.1, 0, 0.2);
  // The camera turned 90 deg about z: its x is the IMU's y.
  config.extrinsics.T_imu_cam = {0, -1, 0, 0, 1, 0, 0, 0.5, 0, 0, 1, 0, 0, 0, 0, 1};
  config.extrinsics.T_cam_thermal = translation(-0.17, 0, 0);
  const dds::TfMessage msg = static_transforms(config, WallTime::from_ns(5));
  ASSERT_EQ(msg.transforms.size(), 3u);
  EXPECT_EQ(msg.transforms[0].child_frame, "velodyne");
  EXPECT_TRUE(msg.transforms[0].p_parent_child_m.isApprox(Eigen::Vector3d(0.1, 0, 0.2)));
  EXPECT_EQ(msg.transforms[2].parent_frame, "base_link");
  EXPECT_EQ(msg.transforms[2].child_frame, "thermal");
  // -0.17 m along the camera's x is -0.17 m along the IMU's y, from the camera at y = 0.5 m.
  EXPECT_TRUE(msg.transforms[2].p_parent_child_m.isApprox(Eigen::Vector3d(0, 0.33, 0), 1e-12));
  EXPECT_TRUE(msg.transforms[2].q_parent_child.isApprox(msg.transforms[1].q_parent_child));
}

}  // namespace
}  // namespace posed
