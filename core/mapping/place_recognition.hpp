#pragma once
// What the loop closer and the localiser both do with a scan before they look for its place: level
// it, describe it (Scan Context) and thin it for registration; and how they find the keyframe whose
// descriptor matches best (ring keys first, then full Scan Contexts over the nearest few), with the
// rotation that match implies as registration's first guess.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstddef>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "core/mapping/scan_context.hpp"

namespace posed::mapping {

/// The rotation that removes `R_world_base`'s roll and pitch and its yaw: a levelled frame whose x
/// is the body's heading projected onto the horizontal (R_level_base = Rz(yaw)^T R). The same for
/// any world frame that differs by a yaw, so odometry and map frames level a keyframe alike.
Eigen::Matrix3d levelling(const Eigen::Matrix3d& R_world_base);

struct DescribedScan {
  Eigen::Matrix3d R_level_base = Eigen::Matrix3d::Identity();
  std::vector<Eigen::Vector3f> points_base;  ///< finite, within range, thinned to voxel_m [m]
  ScanContext context;
};

/// `points_base`: a deskewed scan in base_link; `R_world_base`: its attitude (only roll and pitch
/// matter). The descriptor is made of the points within `context_range_m` (as the map's were:
/// a query must match them), the cloud of those within `cloud_range_m`.
DescribedScan describe_scan(std::span<const Eigen::Vector3f> points_base,
                            const Eigen::Matrix3d& R_world_base, double context_range_m,
                            double cloud_range_m, double voxel_m, const ScanContextConfig& config);

struct DescriptorMatch {
  std::size_t index = 0;  ///< of the matching keyframe [1]
  double distance = 1.0;  ///< Scan Context distance [0..1]
  /// the query's base in the match's base, rotation only: the same place, so no translation
  Eigen::Isometry3d T_match_query_guess = Eigen::Isometry3d::Identity();
};

/// The best Scan Context match below `max_distance` among keyframes [0, count):
/// `context_of(i)` and `level_of(i)` give keyframe i's descriptor and R_level_base. Keyframes
/// without a descriptor (a place an older keyframe maps) are passed over.
template <class ContextOf, class LevelOf>
std::optional<DescriptorMatch> best_descriptor_match(const ScanContext& query,
                                                     const Eigen::Matrix3d& R_level_query,
                                                     std::size_t count, ContextOf context_of,
                                                     LevelOf level_of, int ring_key_candidates,
                                                     double max_distance,
                                                     const ScanContextConfig& config) {
  // Nearest ring keys (heading-invariant), then Scan Context distances over those few.
  std::vector<std::pair<float, std::size_t>> by_ring_key;
  by_ring_key.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const ScanContext& c = context_of(i);
    if (c.ring_key.size() != query.ring_key.size()) continue;
    by_ring_key.emplace_back((c.ring_key - query.ring_key).squaredNorm(), i);
  }
  const auto n =
      std::min<std::size_t>(by_ring_key.size(), static_cast<std::size_t>(ring_key_candidates));
  std::partial_sort(by_ring_key.begin(), by_ring_key.begin() + static_cast<std::ptrdiff_t>(n),
                    by_ring_key.end());
  std::optional<DescriptorMatch> best;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = by_ring_key[k].second;
    const ScanContextMatch match = match_scan_contexts(query, context_of(i), config);
    if (match.distance < (best ? best->distance : max_distance)) {
      // In the levelled frames the query sits at the candidate turned by the match's yaw.
      const Eigen::Matrix3d R_level_c_level_q =
          Eigen::AngleAxisd(match.yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      DescriptorMatch m;
      m.index = i;
      m.distance = match.distance;
      m.T_match_query_guess.linear() = level_of(i).transpose() * R_level_c_level_q * R_level_query;
      best = m;
    }
  }
  return best;
}

}  // namespace posed::mapping
