#include "tools/eval/rpe.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace posed::eval {
namespace {

std::vector<IndexPair> join_successive(const std::vector<std::size_t>& ids) {
  std::vector<IndexPair> pairs;
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

/// T_a^-1 T_b, with the inverse taken as [R^T, -R^T t] (what evo does, also for KITTI
/// rotations that are not exactly orthonormal).
RigidPose relative(const RigidPose& a, const RigidPose& b) {
  return RigidPose{a.R.transpose() * b.R, a.R.transpose() * (b.p_m - a.p_m)};
}

}  // namespace

double rotation_angle_deg(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d axis_sin(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * axis_sin.norm(), 0.5 * (R.trace() - 1.0)) * 180.0 / std::numbers::pi;
}

std::vector<IndexPair> pairs_by_path_length(const std::vector<Eigen::Vector3d>& p_gt_m,
                                            double delta_m) {
  std::vector<std::size_t> ids;
  double path_m = 0.0;
  for (std::size_t i = 0; i < p_gt_m.size(); ++i) {
    if (i > 0) path_m += (p_gt_m[i] - p_gt_m[i - 1]).norm();
    if (path_m >= delta_m) {
      ids.push_back(i);
      path_m = 0.0;
    }
  }
  return join_successive(ids);
}

std::vector<IndexPair> pairs_by_time(const std::vector<TrajectoryTime>& stamps, Duration delta) {
  std::vector<std::size_t> ids;
  if (stamps.empty()) return {};
  ids.push_back(0);
  for (std::size_t i = 1; i < stamps.size(); ++i) {
    if (stamps[i] - stamps[ids.back()] >= delta) ids.push_back(i);
  }
  return join_successive(ids);
}

RpeErrors relative_pose_errors(const std::vector<RigidPose>& gt, const std::vector<RigidPose>& est,
                               const std::vector<IndexPair>& pairs) {
  RpeErrors out;
  out.translation_m.reserve(pairs.size());
  out.rotation_deg.reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    const RigidPose dQ = relative(gt[i], gt[j]);
    const RigidPose dP = relative(est[i], est[j]);
    const RigidPose E = relative(dQ, dP);
    out.translation_m.push_back(E.p_m.norm());
    out.rotation_deg.push_back(rotation_angle_deg(E.R));
  }
  return out;
}

}  // namespace posed::eval
