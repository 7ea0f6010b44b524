#pragma once
// The lidar front end of the lidar-inertial estimator: per scan, deskew with the IMU motion,
// features, scan-to-map against the local map from the IMU-predicted pose; once the back end has
// refined the pose, the scan joins the map if it is a keyframe (moved or turned enough since the
// last one). The steps are separate calls so `posectl bench lio` can time each one (core reads
// no clock). Deterministic; memory bounded by the map radius.

#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "core/lidar/feature_extractor.hpp"
#include "core/lidar/scan_matcher.hpp"
#include "core/lidar/scan_motion.hpp"
#include "core/lidar/voxel_map.hpp"

namespace posed::lidar {

struct LidarOdometryConfig {
  FeatureConfig features;
  ScanMatcherConfig matcher;
  VoxelMapConfig edge_map{0.5, 10, 0.1};
  VoxelMapConfig plane_map{1.0, 20, 0.3};
  float min_range_m = 1.0f;          ///< points nearer are the robot itself [m]
  float max_range_m = 120.0f;        ///< [m]
  double keyframe_distance_m = 1.0;  ///< a scan this far from the last keyframe joins the map
  double keyframe_angle_rad = 0.2;   ///< or turned this much [rad]
  double map_radius_m = 120.0;       ///< map voxels farther from the robot are dropped [m]
};

struct LidarOdometryCounters {
  std::uint64_t scans = 0;       ///< scans matched (or used to start the map)
  std::uint64_t failed = 0;      ///< matches without enough correspondences
  std::uint64_t keyframes = 0;   ///< scans added to the map
  std::uint64_t degenerate = 0;  ///< matches with at least one degenerate direction
};

class LidarOdometry {
 public:
  explicit LidarOdometry(const LidarOdometryConfig& config);

  void deskew(std::span<const LidarPoint> points, HostTime scan_start, const ScanMotion& motion);
  void extract_features();
  /// First scan: starts the map at the prediction and returns it with ok = true.
  ScanMatchResult match(const Eigen::Isometry3d& T_map_lidar_predicted);
  /// After the back end refined the pose: adds the scan to the map; true when it is also a
  /// keyframe (moved or turned enough since the last).
  bool commit(const Eigen::Isometry3d& T_map_lidar_final);
  /// All of the above in order, committing the matched pose.
  ScanMatchResult process(std::span<const LidarPoint> points, HostTime scan_start,
                          const ScanMotion& motion, const Eigen::Isometry3d& T_map_lidar_predicted);

  const std::vector<ScanPoint>& deskewed() const { return deskewed_; }
  const ScanFeatures& features() const { return features_; }
  const std::vector<Eigen::Isometry3d>& keyframe_poses() const { return keyframes_; }
  const VoxelMap& edge_map() const { return edge_map_; }
  const VoxelMap& plane_map() const { return plane_map_; }
  /// Every map point (edges and planes), map frame.
  void map_points(std::vector<Eigen::Vector3f>& out) const;
  const LidarOdometryCounters& counters() const { return counters_; }
  const LidarOdometryConfig& config() const { return config_; }
  /// See ScanMatcher::set_translation_degeneracy.
  void set_translation_degeneracy(double threshold, double information_scale) {
    matcher_.set_translation_degeneracy(threshold, information_scale);
  }
  /// Where the feature extraction's and the scan match's parts run (null: here).
  void set_splitter(WorkSplitter* splitter) {
    extractor_.set_splitter(splitter);
    matcher_.set_splitter(splitter);
  }
  /// Forgets the map and keyframes (re-initialisation after divergence).
  void reset();

 private:
  void add_to_map(const Eigen::Isometry3d& T_map_lidar, bool keyframe);

  LidarOdometryConfig config_;
  FeatureExtractor extractor_;
  ScanMatcher matcher_;
  VoxelMap edge_map_, plane_map_;
  HostTime scan_start_;  ///< of the scan deskew() took: when its points hit the map's voxels
  std::vector<ScanPoint> deskewed_;
  ScanFeatures features_;
  std::vector<Eigen::Vector3f> transformed_;
  std::vector<Eigen::Isometry3d> keyframes_;
  Eigen::Vector3d last_cleanup_m_ = Eigen::Vector3d::Zero();
  LidarOdometryCounters counters_;
};

}  // namespace posed::lidar
