// The IMU stage's decoder for sensor_msgs/Imu imported from a ROS 1 bag (wire format
// ros1:sensor_msgs/Imu, docs/import.md). Standard ROS semantics: angular_velocity [rad/s] and
// linear_acceleration = specific force [m/s^2] in the message's frame, which for M2DGR's
// /handsfree/imu is the A9's own axes (its driver published accel x (-9.8) from the frame's g
// units, as a9_protocol's to_imu_sample does), so imu.R_imu_sensor rotates it into posed's IMU
// frame exactly as it does the A9's frames.
//
// Time: header.stamp is the device stamp and goes through the stage's ClockSync (built from the
// imu section of the config) against the bag's receive time, like every other stream's device
// stamps; imu.clock_kind: none ignores the stamps and takes receive time minus the latency.

#include "daemon/pipeline/imu_stage.hpp"
#include "drivers/common/log.hpp"
#include "drivers/recording/ros1_messages.hpp"

namespace posed::pipeline {

namespace ros1 = drivers::recording::ros1;

void ImuStage::on_ros1_imu(const drivers::RawChunk& chunk) {
  ros1::Imu msg;
  const ros1::Ros1Status status = ros1::decode_imu(chunk.bytes, msg);
  if (status != ros1::Ros1Status::kOk) {
    if (counters_.malformed.fetch_add(1, std::memory_order_relaxed) == 0) {
      POSED_LOG_WARN("imu: malformed sensor_msgs/Imu (%s, %zu B): skipped (said once)",
                     std::string(ros1::to_string(status)).c_str(), chunk.bytes.size());
    }
    return;
  }
  const DeviceTime device_stamp = DeviceTime::from_ns(msg.header.stamp_ns);
  const HostTime stamp = clock_.config().kind == DeviceClockKind::kNone
                             ? chunk.host_receive - clock_.config().latency
                             : clock_.map(device_stamp, chunk.host_receive);
  log_clock_event("imu", clock_.last_event());
  Eigen::Matrix3d R_imu_sensor;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      R_imu_sensor(r, c) =
          mounting_.R_imu_sensor[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
    }
  }
  const auto& w = msg.angular_velocity_radps;
  const auto& a = msg.linear_acceleration_mps2;
  ImuSample sample;
  sample.stamp = stamp;
  sample.device_stamp = device_stamp;
  sample.angular_velocity_radps = R_imu_sensor * Eigen::Vector3d(w[0], w[1], w[2]);
  sample.specific_force_mps2 = R_imu_sensor * Eigen::Vector3d(a[0], a[1], a[2]);
  push(sample);
}

}  // namespace posed::pipeline
