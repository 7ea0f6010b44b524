#include "core/lidar/lidar_odometry.hpp"

#include "core/math/so3.hpp"

namespace posed::lidar {

LidarOdometry::LidarOdometry(const LidarOdometryConfig& config)
    : config_(config),
      extractor_(config.features),
      matcher_(config.matcher),
      edge_map_(config.edge_map),
      plane_map_(config.plane_map) {
  deskewed_.reserve(static_cast<std::size_t>(config.features.rows) *
                    static_cast<std::size_t>(config.features.columns));
}

void LidarOdometry::reset() {
  edge_map_.clear();
  plane_map_.clear();
  keyframes_.clear();
}

void LidarOdometry::deskew(std::span<const LidarPoint> points, HostTime scan_start,
                           const ScanMotion& motion) {
  scan_start_ = scan_start;
  lidar::deskew(points, scan_start, motion, config_.features.columns, config_.min_range_m,
                config_.max_range_m, deskewed_);
}

void LidarOdometry::extract_features() { extractor_.extract(deskewed_, features_); }

ScanMatchResult LidarOdometry::match(const Eigen::Isometry3d& T_map_lidar_predicted) {
  ++counters_.scans;
  if (keyframes_.empty()) {
    ScanMatchResult first;
    first.ok = true;
    first.T_map_lidar = first.T_map_lidar_measured = T_map_lidar_predicted;
    // The first scan defines the map: its pose is as certain as the prediction, not more.
    return first;
  }
  ScanMatchResult r = matcher_.match(features_.edges, features_.planes, edge_map_, plane_map_,
                                     T_map_lidar_predicted);
  if (!r.ok) ++counters_.failed;
  if (r.degenerate_directions > 0) ++counters_.degenerate;
  return r;
}

void LidarOdometry::add_to_map(const Eigen::Isometry3d& T, bool keyframe) {
  const Eigen::Isometry3f Tf = T.cast<float>();
  transformed_.clear();
  for (const Eigen::Vector3f& p : features_.edges) transformed_.push_back(Tf * p);
  edge_map_.insert(transformed_, scan_start_.ns);
  transformed_.clear();
  for (const Eigen::Vector3f& p : features_.planes) transformed_.push_back(Tf * p);
  plane_map_.insert(transformed_, scan_start_.ns);
  if (!keyframe) return;
  keyframes_.push_back(T);
  ++counters_.keyframes;
  // Bounded memory: every 10 m travelled, forget what is out of reach.
  if ((T.translation() - last_cleanup_m_).norm() > 10.0) {
    last_cleanup_m_ = T.translation();
    const Eigen::Vector3f centre = T.translation().cast<float>();
    edge_map_.remove_far_from(centre, config_.map_radius_m);
    plane_map_.remove_far_from(centre, config_.map_radius_m);
  }
}

bool LidarOdometry::commit(const Eigen::Isometry3d& T_map_lidar_final) {
  // Every matched scan joins the map (as FAST-LIO2 does): the map fills in between the rings of
  // one scan quickly, and the per-voxel point limit and spacing keep it from growing denser.
  bool keyframe = keyframes_.empty();
  if (!keyframe) {
    const Eigen::Isometry3d& last = keyframes_.back();
    const double moved = (T_map_lidar_final.translation() - last.translation()).norm();
    const double turned =
        so3::log(Eigen::Matrix3d(last.linear().transpose() * T_map_lidar_final.linear())).norm();
    keyframe = moved >= config_.keyframe_distance_m || turned >= config_.keyframe_angle_rad;
  }
  add_to_map(T_map_lidar_final, keyframe);
  return keyframe;
}

ScanMatchResult LidarOdometry::process(std::span<const LidarPoint> points, HostTime scan_start,
                                       const ScanMotion& motion,
                                       const Eigen::Isometry3d& T_map_lidar_predicted) {
  deskew(points, scan_start, motion);
  extract_features();
  ScanMatchResult r = match(T_map_lidar_predicted);
  if (r.ok) commit(r.T_map_lidar);
  return r;
}

void LidarOdometry::map_points(std::vector<Eigen::Vector3f>& out) const {
  edge_map_.collect(out);
  plane_map_.collect(out);
}

}  // namespace posed::lidar
