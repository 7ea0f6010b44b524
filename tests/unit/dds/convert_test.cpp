// Plain structs <-> generated C samples: stamps (ROS keeps nanosec in [0, 1e9)), frames, and the
// quaternion order (ROS x y z w, Eigen's constructor w x y z).

#include "daemon/dds/convert.hpp"

#include <gtest/gtest.h>

namespace posed::dds {
namespace {

TEST(DdsConvert, StampSplitsIntoSecAndNanosec) {
  const auto t = detail::to_ros_time(WallTime::from_ns(1'700'000'000'123'456'789));
  EXPECT_EQ(t.sec, 1'700'000'000);
  EXPECT_EQ(t.nanosec, 123'456'789u);
  EXPECT_EQ(detail::from_ros_time(t).ns, 1'700'000'000'123'456'789);
}

TEST(DdsConvert, NegativeStampKeepsNanosecPositive) {
  const auto t = detail::to_ros_time(WallTime::from_ns(-1'500'000'000));
  EXPECT_EQ(t.sec, -2);
  EXPECT_EQ(t.nanosec, 500'000'000u);
  EXPECT_EQ(detail::from_ros_time(t).ns, -1'500'000'000);
  const auto whole = detail::to_ros_time(WallTime::from_ns(-2'000'000'000));
  EXPECT_EQ(whole.sec, -2);
  EXPECT_EQ(whole.nanosec, 0u);
}

TEST(DdsConvert, OdomFieldsLandInRosPlaces) {
  OdomMessage msg;
  msg.stamp = WallTime::from_ns(5'000'000'001);
  msg.p_map_base_m = {1, 2, 3};
  msg.q_map_base = Eigen::Quaterniond(0.8, 0.0, 0.0, 0.6);  // w x y z
  msg.v_base_mps = {0.5, -0.1, 0.0};
  msg.w_base_radps = {0.0, 0.0, 0.2};
  for (std::size_t i = 0; i < 36; ++i) {
    msg.pose_covariance[i] = static_cast<double>(i);
    msg.twist_covariance[i] = -static_cast<double>(i);
  }
  nav_msgs_msg_dds__Odometry_ c{};
  detail::fill_odom(msg, c);
  EXPECT_EQ(c.header.stamp.sec, 5);
  EXPECT_EQ(c.header.stamp.nanosec, 1u);
  EXPECT_EQ(c.pose.pose.position.z, 3.0);
  EXPECT_EQ(c.pose.pose.orientation.z, 0.6);  // ROS order x y z w
  EXPECT_EQ(c.pose.pose.orientation.w, 0.8);
  EXPECT_EQ(c.twist.twist.linear.y, -0.1);
  EXPECT_EQ(c.twist.twist.angular.z, 0.2);
  EXPECT_EQ(c.pose.covariance[7], 7.0);
  EXPECT_EQ(c.twist.covariance[35], -35.0);
  EXPECT_EQ(c.header.frame_id, nullptr);  // the Publisher's, not fill_odom's

  const OdomMessage back = detail::to_plain(c);
  EXPECT_EQ(back.stamp, msg.stamp);
  EXPECT_EQ(back.p_map_base_m, msg.p_map_base_m);
  EXPECT_EQ(back.q_map_base.coeffs(), msg.q_map_base.coeffs());
  EXPECT_EQ(back.v_base_mps, msg.v_base_mps);
  EXPECT_EQ(back.w_base_radps, msg.w_base_radps);
  EXPECT_EQ(back.pose_covariance, msg.pose_covariance);
  EXPECT_EQ(back.twist_covariance, msg.twist_covariance);
}

TEST(DdsConvert, PoseRoundTrips) {
  PoseMessage msg;
  msg.stamp = WallTime::from_ns(42);
  msg.p_map_base_m = {-1, 0.5, 7};
  msg.q_map_base = Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5);
  geometry_msgs_msg_dds__PoseStamped_ c{};
  detail::fill_pose(msg, c);
  EXPECT_EQ(c.pose.orientation.x, 0.5);
  EXPECT_EQ(c.pose.orientation.y, -0.5);
  const PoseMessage back = detail::to_plain(c);
  EXPECT_EQ(back.stamp, msg.stamp);
  EXPECT_EQ(back.p_map_base_m, msg.p_map_base_m);
  EXPECT_EQ(back.q_map_base.coeffs(), msg.q_map_base.coeffs());
}

TEST(DdsConvert, StatusReusesStreamBufferAndRoundTrips) {
  StatusMessage msg;
  msg.stamp = WallTime::from_ns(9'000'000'000);
  msg.version = "posed 0.1.0";
  msg.estimator_mode = "degenerate";
  msg.estimator.scans_used = 1234;
  msg.estimator.scans_degenerate = 56;
  msg.estimator.reinitialisations = 2;
  msg.estimator.degenerate_directions = 1;
  msg.estimator.gyro_bias_radps = {0.001, -0.002, 0.003};
  msg.estimator.accel_bias_mps2 = {0.04, -0.05, 0.06};
  msg.camera.mode = "fused";
  msg.camera.frames = 300;
  msg.camera.frames_unusable = 3;
  msg.camera.features = 287;
  msg.camera.depth_associated = 120;
  msg.camera.match_success_rate = 0.93;
  msg.camera.confidence = {0.1, 0.5, 0.6};
  msg.camera.omega = {90.0, 2.0, 1.5};
  msg.uptime_s = 12.5;
  msg.summary = "ok";
  msg.visual[0].configured = true;
  msg.visual[0].factors = 40;
  msg.visual[0].keyframe_factors = 31;
  msg.visual[0].still = 7;
  msg.visual[0].residual_median = 1.5;
  msg.mapping = {"localised", 120, 3, 17, 2.25, 4};
  for (const char* name : {"imu", "lidar", "color"}) {
    StreamStatusMessage s;
    s.name = name;
    s.rate_hz = 10.0;
    s.received = 100;
    s.decoded = 99;
    s.dropped = 1;
    s.malformed = 0;
    s.clock_offset_ns = -5;
    s.clock_drift_ppm = 1.5;
    s.clock_jitter_ns = 2.5;
    s.clock_uncertainty_ns = 3.5;
    s.clock_state = "locked";
    s.health = "ok";
    msg.streams.push_back(s);
  }
  std::vector<posed_msgs_msg_dds__StreamStatus_> buffer(8);
  const auto* storage = buffer.data();
  posed_msgs_msg_dds__Status_ c{};
  detail::fill_status(msg, c, buffer);
  EXPECT_EQ(buffer.data(), storage);  // 3 streams fit: no reallocation
  EXPECT_EQ(c.streams._length, 3u);
  EXPECT_FALSE(c.streams._release);
  EXPECT_EQ(c.version, msg.version.c_str());  // points into msg, no copy

  const StatusMessage back = detail::to_plain(c);
  EXPECT_EQ(back.stamp, msg.stamp);
  EXPECT_EQ(back.version, msg.version);
  EXPECT_EQ(back.estimator_mode, msg.estimator_mode);
  EXPECT_EQ(back.estimator.scans_used, 1234u);
  EXPECT_EQ(back.estimator.scans_degenerate, 56u);
  EXPECT_EQ(back.estimator.reinitialisations, 2u);
  EXPECT_EQ(back.estimator.degenerate_directions, 1);
  EXPECT_TRUE(back.visual[0].configured);
  EXPECT_EQ(back.visual[0].factors, 40u);
  EXPECT_EQ(back.visual[0].keyframe_factors, 31u);
  EXPECT_EQ(back.visual[0].still, 7);
  EXPECT_EQ(back.visual[0].residual_median, 1.5);
  EXPECT_EQ(back.estimator.gyro_bias_radps, msg.estimator.gyro_bias_radps);
  EXPECT_EQ(back.estimator.accel_bias_mps2, msg.estimator.accel_bias_mps2);
  EXPECT_EQ(back.camera.mode, "fused");
  EXPECT_EQ(back.camera.frames, 300u);
  EXPECT_EQ(back.camera.frames_unusable, 3u);
  EXPECT_EQ(back.camera.features, 287);
  EXPECT_EQ(back.camera.depth_associated, 120);
  EXPECT_EQ(back.camera.match_success_rate, 0.93);
  EXPECT_EQ(back.camera.confidence, msg.camera.confidence);
  EXPECT_EQ(back.camera.omega, msg.camera.omega);
  EXPECT_EQ(back.uptime_s, msg.uptime_s);
  EXPECT_EQ(back.summary, msg.summary);
  EXPECT_EQ(c.mapping.state, msg.mapping.state.c_str());  // points into msg, no copy
  EXPECT_EQ(back.mapping.state, "localised");
  EXPECT_EQ(back.mapping.keyframes, 120u);
  EXPECT_EQ(back.mapping.loops, 3u);
  EXPECT_EQ(back.mapping.fixes, 17u);
  EXPECT_EQ(back.mapping.correction_m, 2.25);
  EXPECT_EQ(back.mapping.scans_skipped, 4u);
  ASSERT_EQ(back.streams.size(), 3u);
  EXPECT_EQ(back.streams[1].name, "lidar");
  EXPECT_EQ(back.streams[2].clock_offset_ns, -5);
  EXPECT_EQ(back.streams[0].clock_uncertainty_ns, 3.5);

  msg.streams.resize(10);  // more streams than ever before: the buffer grows once
  detail::fill_status(msg, c, buffer);
  EXPECT_EQ(buffer.size(), 10u);
  EXPECT_EQ(c.streams._length, 10u);
  EXPECT_EQ(c.streams._buffer, buffer.data());
}

// Without a mapping stage the status says so rather than leaving the state empty.
TEST(DdsConvert, StatusWithoutAMappingStageSaysOff) {
  const StatusMessage msg;
  std::vector<posed_msgs_msg_dds__StreamStatus_> buffer;
  posed_msgs_msg_dds__Status_ c{};
  detail::fill_status(msg, c, buffer);
  EXPECT_STREQ(c.mapping.state, "off");
  const StatusMessage back = detail::to_plain(c);
  EXPECT_EQ(back.mapping.state, "off");
  EXPECT_EQ(back.mapping.keyframes, 0u);
  EXPECT_EQ(back.mapping.correction_m, 0.0);
}

}  // namespace
}  // namespace posed::dds
