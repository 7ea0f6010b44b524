#include "core/fusion/depth_cloud.hpp"

#include <algorithm>

namespace posed::fusion {

DepthCloud::DepthCloud(const DepthCloudConfig& config) : config_(config) {
  config_.view_axis_lidar.normalize();
}

void DepthCloud::add_scan(HostTime stamp, const Eigen::Isometry3d& T_map_lidar,
                          std::span<const lidar::ScanPoint> points_lidar) {
  Scan scan;
  scan.stamp = stamp;
  if (!spare_.empty()) {
    scan.p_map_m = std::move(spare_.back());
    spare_.pop_back();
  }
  scan.p_map_m.clear();
  const Eigen::Vector3f axis = config_.view_axis_lidar.cast<float>();
  std::size_t in_front = 0;
  for (const lidar::ScanPoint& p : points_lidar) in_front += p.p.dot(axis) > 0.f ? 1 : 0;
  // An even stride over the points in front keeps the scan's coverage while bounding the cost.
  const std::size_t stride =
      std::max<std::size_t>(1, (in_front + config_.max_points_per_scan - 1) /
                                   std::max<std::size_t>(1, config_.max_points_per_scan));
  const Eigen::Matrix3f R = T_map_lidar.linear().cast<float>();
  const Eigen::Vector3f t = T_map_lidar.translation().cast<float>();
  scan.p_map_m.reserve(in_front / stride + 1);
  std::size_t k = 0;
  for (const lidar::ScanPoint& p : points_lidar) {
    if (p.p.dot(axis) <= 0.f) continue;
    if (k++ % stride == 0) scan.p_map_m.push_back(R * p.p + t);
  }
  scans_.push_back(std::move(scan));
}

void DepthCloud::points_in_camera(HostTime t, const Eigen::Isometry3d& T_map_cam,
                                  std::vector<Eigen::Vector3f>& out) {
  while (!scans_.empty() && scans_.front().stamp < t - config_.window) {
    spare_.push_back(std::move(scans_.front().p_map_m));
    scans_.pop_front();
  }
  out.clear();
  const Eigen::Isometry3d T_cam_map = T_map_cam.inverse();
  const Eigen::Matrix3f R = T_cam_map.linear().cast<float>();
  const Eigen::Vector3f tr = T_cam_map.translation().cast<float>();
  for (const Scan& s : scans_) {
    // A scan ending after the frame (the merge hands frames and scans over by stamp, so at most
    // one, by less than a rotation) still describes the same surfaces.
    for (const Eigen::Vector3f& p : s.p_map_m) out.push_back(R * p + tr);
  }
}

}  // namespace posed::fusion
