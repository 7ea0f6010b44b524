// The lidar stage's decoder for sensor_msgs/PointCloud2 imported from a ROS 1 bag (wire format
// ros1:sensor_msgs/PointCloud2, docs/import.md): the cloud becomes one LidarScan straight away
// (drivers/recording/ros1_cloud_scan.hpp), with no packet decoder or scan assembler.
//
// Time: header.stamp is taken as the recording's host clock, without a ClockSync. A bag's stamps
// are ROS time, which the import made the recording's host clock, and a cloud is published only
// after its whole rotation (plus conversion), so a lower-envelope fit of stamp against receive
// time would shift every scan by that publishing delay against the IMU. The per-point `time`
// field places each point within the scan.

#include "daemon/pipeline/lidar_stage.hpp"
#include "drivers/common/log.hpp"
#include "drivers/recording/ros1_messages.hpp"

namespace posed::pipeline {

namespace ros1 = drivers::recording::ros1;

void LidarStage::handle_ros1_cloud(const drivers::RawChunk& chunk) {
  ros1::PointCloud2 cloud;
  const ros1::Ros1Status status = ros1::decode_point_cloud2(chunk.bytes, cloud);
  if (status != ros1::Ros1Status::kOk) {
    if (counters_.malformed.fetch_add(1, std::memory_order_relaxed) == 0) {
      POSED_LOG_WARN("lidar: malformed sensor_msgs/PointCloud2 (%s, %zu B): skipped (said once)",
                     std::string(ros1::to_string(status)).c_str(), chunk.bytes.size());
    }
    return;
  }
  if (!cloud_decoder_) {
    cloud_decoder_ = std::make_unique<ros1::CloudScanDecoder>(
        pool_, ros1::CloudScanConfig{.min_range_m = static_cast<float>(config_.lidar.min_range_m),
                                     .max_range_m = static_cast<float>(config_.lidar.max_range_m),
                                     .ring_elevations_rad = ring_elevations_rad_});
  }
  const HostTime stamp = HostTime::from_ns(cloud.header.stamp_ns);
  LidarScan scan;
  ros1::CloudScanInfo info;
  const ros1::CloudScanStatus s = cloud_decoder_->decode(cloud, stamp, scan, info);
  if (s == ros1::CloudScanStatus::kNoBuffer) {
    counters_.dropped.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (s == ros1::CloudScanStatus::kNoXyz || s == ros1::CloudScanStatus::kBigEndian) {
    if (counters_.malformed.fetch_add(1, std::memory_order_relaxed) == 0) {
      POSED_LOG_WARN("lidar: PointCloud2 unusable (%s): skipped (said once)",
                     std::string(ros1::to_string(s)).c_str());
    }
    return;
  }
  if (!reported_cloud_layout_) {
    reported_cloud_layout_ = true;
    if (!info.has_time) {
      POSED_LOG_WARN(
          "lidar: the clouds have no per-point 'time' field: every point is stamped "
          "at header.stamp, deskew is off");
    }
    if (info.derived_ring) {
      POSED_LOG_INFO(
          "lidar: the clouds have no 'ring' field: rings derived from elevation over "
          "%zu beams",
          ring_elevations_rad_.size());
    }
  }
  if (s == ros1::CloudScanStatus::kTimeTooLong) {
    counters_.malformed.fetch_add(1, std::memory_order_relaxed);  // kept, times clamped
  }
  counters_.decoded.fetch_add(1, std::memory_order_relaxed);
  // The stamps are the host clock already: an identity mapping, locked from the first cloud.
  cloud_clock_.state = SyncState::kLocked;
  cloud_clock_.last_device_stamp = DeviceTime::from_ns(cloud.header.stamp_ns);
  cloud_clock_.last_arrival = chunk.host_receive;
  ++cloud_clock_.samples;
  if (cloud_clock_.samples % 16 == 1) counters_.publish_clock(cloud_clock_);
  push_scan(std::move(scan));
  consumer_.signal();
}

}  // namespace posed::pipeline
