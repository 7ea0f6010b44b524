#pragma once
// The local map for scan-to-map matching: points in map frame in a hash of voxels, each voxel
// holding at most `max_points_per_voxel` points at least `min_point_distance_m` apart (so the map
// keeps its spread, not its density), as iVox (FAST-LIO2's successor) and KISS-ICP do. Nearest
// neighbours come from the voxel of the query and its 26 neighbours: exact within one voxel size,
// approximate beyond, which is what correspondences need. Bounded: remove_far_from() drops voxels
// outside a radius, so memory follows the robot, not the run.

#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace posed::lidar {

struct VoxelMapConfig {
  double voxel_m = 1.0;               ///< voxel edge [m]
  int max_points_per_voxel = 20;      ///< [1]
  double min_point_distance_m = 0.1;  ///< new points closer than this to one held are skipped
};

class VoxelMap {
 public:
  explicit VoxelMap(const VoxelMapConfig& config);

  /// Adds map-frame points.
  void insert(const std::vector<Eigen::Vector3f>& points_map);
  /// Up to `k` nearest held points within `max_distance_m` of `query`, nearest first; returns
  /// how many. `out` must have room for k.
  int nearest(const Eigen::Vector3f& query, int k, float max_distance_m,
              Eigen::Vector3f* out) const;
  /// Removes every voxel whose centre is farther than `radius_m` from `centre`.
  std::size_t remove_far_from(const Eigen::Vector3f& centre, double radius_m);

  std::size_t voxels() const { return index_.size(); }
  std::size_t points() const { return points_; }
  /// Every held point (for export).
  void collect(std::vector<Eigen::Vector3f>& out) const;
  void clear();

 private:
  struct Voxel {
    std::vector<Eigen::Vector3f> points;  // reserved to max_points_per_voxel on creation
  };
  std::uint64_t key_of(const Eigen::Vector3i& v) const;
  Eigen::Vector3i voxel_of(const Eigen::Vector3f& p) const;

  VoxelMapConfig config_;
  float inv_voxel_;
  std::unordered_map<std::uint64_t, std::uint32_t> index_;  // key -> slot in voxels_
  std::vector<Voxel> voxels_;
  std::vector<std::uint32_t> free_;  // recycled slots
  std::size_t points_ = 0;
};

}  // namespace posed::lidar
