#pragma once
// Relative pose error (evo's RPE): for each pair (i, j) chosen by a delta criterion on the
// ground truth, E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) with Q ground truth and P the (aligned)
// estimate; the translation part is |t(E)| [m], the rotation part the angle of R(E) [deg].

#include <Eigen/Core>
#include <cstddef>
#include <utility>
#include <vector>

#include "core/time.hpp"
#include "tools/eval/trajectory.hpp"

namespace posed::eval {

using IndexPair = std::pair<std::size_t, std::size_t>;

/// Consecutive pairs by travelled path length, exactly as evo's filter_pairs_by_path
/// (all_pairs off): the path is accumulated from the first pose, every pose where it reaches
/// `delta_m` becomes a pair boundary and the accumulator restarts, and pairs join successive
/// boundaries. (evo's quirk kept for comparable figures: the first boundary is the first pose
/// at >= delta_m, not pose 0.)
std::vector<IndexPair> pairs_by_path_length(const std::vector<Eigen::Vector3d>& p_gt_m,
                                            double delta_m);

/// Consecutive pairs by elapsed time (evo has no time criterion; this is its analogue): the
/// first pair starts at pose 0 and ends at the first pose at least `delta` later, which starts
/// the next pair. `stamps` increase.
std::vector<IndexPair> pairs_by_time(const std::vector<TrajectoryTime>& stamps, Duration delta);

/// A pose T_world_body as rotation and translation.
struct RigidPose {
  /// rotation body -> world [1]
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  /// body origin in the world [m]
  Eigen::Vector3d p_m = Eigen::Vector3d::Zero();
};

struct RpeErrors {
  /// |t(E)| per pair [m]
  std::vector<double> translation_m;
  /// angle of R(E) per pair [deg]
  std::vector<double> rotation_deg;
};

/// Angle of the rotation `R` [deg], from atan2 of its skew and symmetric parts: accurate near
/// 0 and 180 deg, where acos of the trace loses half the digits.
double rotation_angle_deg(const Eigen::Matrix3d& R);

/// Errors for `pairs` of indices into `gt` and `est` (equal length, corresponding poses).
RpeErrors relative_pose_errors(const std::vector<RigidPose>& gt, const std::vector<RigidPose>& est,
                               const std::vector<IndexPair>& pairs);

}  // namespace posed::eval
