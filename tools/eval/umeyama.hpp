#pragma once
// Least-squares similarity between two point sets (S. Umeyama, "Least-squares estimation of
// transformation parameters between two point patterns", PAMI 1991), as evo's
// `umeyama_alignment`: finds R, t, s minimising sum |p_gt - (s R p_est + t)|^2.

#include <Eigen/Core>
#include <vector>

namespace posed::eval {

/// p_gt = scale * R_gt_est * p_est + t_gt_est
struct Sim3 {
  /// rotation estimate world -> ground-truth world [1]
  Eigen::Matrix3d R_gt_est = Eigen::Matrix3d::Identity();
  /// estimate world origin in the ground-truth world [m]
  Eigen::Vector3d t_gt_est_m = Eigen::Vector3d::Zero();
  /// ground-truth metres per estimate unit; 1 for SE(3) [1]
  double scale = 1.0;

  Eigen::Vector3d apply(const Eigen::Vector3d& p_est) const {
    return scale * (R_gt_est * p_est) + t_gt_est_m;
  }
};

/// Aligns `p_est` onto `p_gt` (same length, pairwise corresponding). with_scale=false is SE(3)
/// (scale 1), true is Sim(3). Throws EvalError when fewer than 3 points are given or the
/// rotation is not determined: all points coincident or on one line (the cross-covariance has
/// rank < 2), or, with scale, the estimate points have no spread.
Sim3 umeyama(const std::vector<Eigen::Vector3d>& p_est, const std::vector<Eigen::Vector3d>& p_gt,
             bool with_scale);

}  // namespace posed::eval
