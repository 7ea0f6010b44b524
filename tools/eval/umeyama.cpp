#include "tools/eval/umeyama.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <string>

#include "tools/eval/eval_error.hpp"

namespace posed::eval {

Sim3 umeyama(const std::vector<Eigen::Vector3d>& p_est, const std::vector<Eigen::Vector3d>& p_gt,
             bool with_scale) {
  const std::size_t n = p_est.size();
  if (n != p_gt.size()) {
    throw EvalError("alignment: " + std::to_string(n) + " estimate points but " +
                    std::to_string(p_gt.size()) + " ground-truth points");
  }
  if (n < 3) {
    throw EvalError("alignment needs at least 3 point pairs, got " + std::to_string(n));
  }
  const double inv_n = 1.0 / static_cast<double>(n);
  Eigen::Vector3d mean_est = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_gt = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mean_est += p_est[i];
    mean_gt += p_gt[i];
  }
  mean_est *= inv_n;
  mean_gt *= inv_n;

  double var_est = 0.0;                           // Umeyama eq. 36
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();  // eq. 38: cov(gt, est)
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d de = p_est[i] - mean_est;
    var_est += de.squaredNorm();
    cov += (p_gt[i] - mean_gt) * de.transpose();
  }
  var_est *= inv_n;
  cov *= inv_n;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  // With rank 2 (a planar trajectory, the usual case for a ground robot) the optimum is still
  // unique thanks to the reflection fix below; with rank <= 1 any rotation about the line fits.
  if (!(d(0) > 0.0) || d(1) <= 1e-9 * d(0)) {
    throw EvalError(
        "degenerate alignment: the associated positions are coincident or on one line, so the "
        "rotation is undetermined (singular values of the cross-covariance " +
        std::to_string(d(0)) + ", " + std::to_string(d(1)) + ", " + std::to_string(d(2)) +
        " m^2); use --align none");
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) {
    S(2, 2) = -1.0;  // a reflection fits better; take the best proper rotation instead (eq. 43)
  }
  Sim3 T;
  T.R_gt_est = svd.matrixU() * S * svd.matrixV().transpose();  // eq. 40
  if (with_scale) {
    if (!(var_est > 0.0)) {
      throw EvalError("degenerate Sim(3) alignment: the estimate positions have no spread");
    }
    T.scale = (d.asDiagonal() * S).trace() / var_est;  // eq. 42
  }
  T.t_gt_est_m = mean_gt - T.scale * T.R_gt_est * mean_est;  // eq. 41
  return T;
}

}  // namespace posed::eval
