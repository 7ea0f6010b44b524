#pragma once
// A keyframe map: what the mapping layer built and what localisation runs on (docs/mapping.md,
// Map files). Every keyframe with its optimised pose in the map frame, its thinned cloud in its
// own base_link frame and its Scan Context, plus the pose graph's edges. Plain data: the
// LoopCloser makes one (snapshot()), drivers/recording/map_directory writes and reads one, the
// Localiser tracks against one.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "core/mapping/compact_cloud.hpp"
#include "core/mapping/pose_graph.hpp"
#include "core/mapping/scan_context.hpp"

namespace posed::mapping {

struct MapKeyframe {
  /// the keyframe's stamp on the clock its writer chose (posed writes the wall clock, as its
  /// poses and TUM files are stamped) [ns]
  std::int64_t stamp_ns = 0;
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  CompactCloud points_base;  ///< thinned to KeyframeMap::voxel_m [m]
  ScanContext context;       ///< of the full scan, levelled
};

struct KeyframeMap {
  double voxel_m = 0.3;  ///< the keyframe clouds' resolution [m]
  /// the keyframe clouds' reach: no point farther from its keyframe (a query is cut the same) [m]
  double max_range_m = 60.0;
  ScanContextConfig scan_context;  ///< how the descriptors were made (a query must match it)
  std::vector<MapKeyframe> keyframes;
  std::vector<PoseGraphEdge> edges;  ///< odometry and loop edges between keyframe indices
};

}  // namespace posed::mapping
