#pragma once
// The whole-run point cloud map for export (posed --save-map, posectl export --pcd). The scan
// matcher's local map forgets what is out of reach to stay bounded; this one keeps every
// keyframe's deskewed points, merged into a voxel grid (one centroid per voxel) so its memory
// grows with the volume explored, not with the time driven. Only built when asked for.

#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "core/lidar/scan_motion.hpp"

namespace posed::lidar {

class MapCloud {
 public:
  /// `voxel_m`: edge of a voxel; points closer than this merge into one [m].
  explicit MapCloud(double voxel_m = 0.1);

  /// Adds a keyframe's points (lidar frame at the scan's end) at its final pose.
  void add(std::span<const ScanPoint> points_lidar, const Eigen::Isometry3d& T_map_lidar);
  /// One point per occupied voxel (the centroid of what fell in it), map frame [m], in a stable
  /// order (by voxel key) so two identical runs export identical files.
  void collect(std::vector<Eigen::Vector3f>& out) const;
  std::size_t voxels() const { return voxels_.size(); }
  double voxel_m() const { return voxel_m_; }

 private:
  struct Accum {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::uint32_t count = 0;
  };
  double voxel_m_;
  std::unordered_map<std::uint64_t, Accum> voxels_;
};

}  // namespace posed::lidar
