#pragma once
// Absolute trajectory error, translation part (evo's APE with --pose_relation trans_part):
// per associated pose, the distance between the ground-truth position and the aligned
// estimate position.

#include <Eigen/Core>
#include <vector>

namespace posed::eval {

/// |p_gt_m[i] - p_est_aligned_m[i]| for every i [m]; the vectors have equal length.
std::vector<double> ate_translation_errors_m(const std::vector<Eigen::Vector3d>& p_gt_m,
                                             const std::vector<Eigen::Vector3d>& p_est_aligned_m);

}  // namespace posed::eval
