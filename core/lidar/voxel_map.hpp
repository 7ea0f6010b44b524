#pragma once
// The local map for scan-to-map matching: points in map frame in a hash of voxels, each voxel
// holding at most `max_points_per_voxel` points at least `min_point_distance_m` apart (so the map
// keeps its spread, not its density), as iVox (FAST-LIO2's successor) and KISS-ICP do. Nearest
// neighbours come from the voxel of the query and its 26 neighbours: exact within one voxel size,
// approximate beyond, which is what correspondences need. Bounded: remove_far_from() drops voxels
// outside a radius, so memory follows the robot, not the run.
//
// Moving things (people, vehicles) leave a trail of points behind them, and a scan matched to
// that trail takes their motion for the robot's: in a tunnel whose walls cannot pin the axis, a
// person walking beside the robot is what pins it, wrongly. So with `confirm_after_s` a point is
// matched against only once a scan `confirm_after_s` or more later found the surface again (a
// point within half a voxel of it): the world stays where it was, a walker does not. A point not
// found again within twice that span gives its place in a full voxel to a new one. While the map
// itself is younger than the span, every point is used, or nothing could start it.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/lidar/voxel_index.hpp"

namespace posed::lidar {

struct VoxelMapConfig {
  double voxel_m = 1.0;               ///< voxel edge [m]
  int max_points_per_voxel = 20;      ///< [1]
  double min_point_distance_m = 0.1;  ///< new points closer than this to one held are skipped
  /// a voxel is matched against once scans have hit it over this long (0: at once) [s]
  double confirm_after_s = 0;
};

class VoxelMap {
 public:
  explicit VoxelMap(const VoxelMapConfig& config);

  /// Adds map-frame points of a scan taken at `stamp_ns` (the scans' clock, increasing).
  void insert(const std::vector<Eigen::Vector3f>& points_map, std::int64_t stamp_ns = 0);
  /// Up to `k` nearest held points within `max_distance_m` of `query`, nearest first; returns
  /// how many. `out` must have room for k.
  int nearest(const Eigen::Vector3f& query, int k, float max_distance_m,
              Eigen::Vector3f* out) const;
  /// Removes every voxel whose centre is farther than `radius_m` from `centre`.
  std::size_t remove_far_from(const Eigen::Vector3f& centre, double radius_m);

  std::size_t voxels() const { return index_.size(); }
  /// points matched against (confirm_after_s), of points()
  std::size_t confirmed_points() const;
  std::size_t points() const { return points_; }
  /// Every held point that is matched against (for export).
  void collect(std::vector<Eigen::Vector3f>& out) const;
  void clear();

 private:
  // Storage is flat, a slot per voxel: its points at [slot * cap, slot * cap + count) of one
  // pool, so a lookup costs the index probe and the points, not a vector header between them.
  /// The slot of the voxel `key`, made empty if the map had none.
  std::uint32_t slot_for(std::uint64_t key);

  static constexpr float kConfirmed = -1.f;
  std::uint64_t key_of(const Eigen::Vector3i& v) const;
  Eigen::Vector3i voxel_of(const Eigen::Vector3f& p) const;

  VoxelMapConfig config_;
  float inv_voxel_;
  std::size_t cap_;                        // max_points_per_voxel
  VoxelIndex index_;                       // key -> slot
  std::vector<std::uint64_t> slot_key_;    // per slot; VoxelIndex::kEmptyKey: free
  std::vector<std::uint32_t> slot_count_;  // points held per slot
  std::vector<Eigen::Vector3f> pool_;      // slot * cap_ + i
  /// with confirm_after_s, per point of pool_: when it was first seen (map time) or kConfirmed [s]
  std::vector<float> first_seen_s_;
  std::vector<std::uint32_t> free_;  // recycled slots
  std::size_t points_ = 0;
  float confirm_s_ = 0;
  float confirm_radius_m_ = 0;     // a new point this near an old one found it again
  std::int64_t map_start_ns_ = 0;  // the first insert's stamp
  bool started_ = false;
  bool young_ = false;  // the newest insert was within confirm_after_s of the first
};

}  // namespace posed::lidar
