#pragma once
// sensor_msgs/PointCloud2 messages from what the estimator holds (pure functions; CloudOutput
// publishes them): a matched scan for rt/posed/cloud, the local map for rt/posed/map.

#include <Eigen/Core>
#include <span>
#include <string>

#include "core/estimator/fusion_core.hpp"
#include "daemon/dds/messages.hpp"

namespace posed {

/// rt/posed/cloud's point layout, as the ROS 2 Velodyne driver's PointXYZIRT names it (packed,
/// 22 bytes): x y z [m] and intensity [0..255] float32, ring uint16 (0 = lowest beam), time
/// float32 [s]: the firing relative to header.stamp, which is the scan's end where the points are
/// deskewed to, so every time is <= 0.
inline constexpr std::uint32_t kScanPointStep = 22;

/// Replaces `out` with `scan`'s points in the lidar frame `frame_id` at `stamp` (the scan's end
/// on the wall clock). Reuses out.data's capacity: no allocation once it has held a scan.
void scan_cloud(const MatchedScan& scan, WallTime stamp, const std::string& frame_id,
                dds::CloudMessage& out);

/// Replaces `out` with `points_map_m` (x y z float32, 12 bytes a point) in `frame_id`.
void map_cloud(std::span<const Eigen::Vector3f> points_map_m, WallTime stamp,
               const std::string& frame_id, dds::CloudMessage& out);

}  // namespace posed
