#include "tools/eval/ate.hpp"

#include <algorithm>

namespace posed::eval {

std::vector<double> ate_translation_errors_m(const std::vector<Eigen::Vector3d>& p_gt_m,
                                             const std::vector<Eigen::Vector3d>& p_est_aligned_m) {
  const std::size_t n = std::min(p_gt_m.size(), p_est_aligned_m.size());
  std::vector<double> errors(n);
  for (std::size_t i = 0; i < n; ++i) errors[i] = (p_gt_m[i] - p_est_aligned_m[i]).norm();
  return errors;
}

}  // namespace posed::eval
