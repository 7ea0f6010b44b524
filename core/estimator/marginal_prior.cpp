#include "core/estimator/marginal_prior.hpp"

#include "core/estimator/pose_manifold.hpp"

namespace posed::estimator {

MarginalPrior::MarginalPrior(std::vector<PriorBlock> blocks, const Eigen::MatrixXd& J,
                             const Eigen::VectorXd& r0)
    : blocks_(std::move(blocks)), J_(J), r0_(r0) {
  int offset = 0;
  for (const PriorBlock& b : blocks_) {
    offsets_.push_back(offset);
    offset += b.tangent_size();
    mutable_parameter_block_sizes()->push_back(b.ambient_size);
  }
  set_num_residuals(static_cast<int>(J_.rows()));
}

bool MarginalPrior::Evaluate(double const* const* parameters, double* residuals,
                             double** jacobians) const {
  static const PoseManifold manifold;
  Eigen::VectorXd dx(J_.cols());
  for (std::size_t k = 0; k < blocks_.size(); ++k) {
    const PriorBlock& b = blocks_[k];
    if (b.is_pose()) {
      manifold.Minus(parameters[k], b.x0.data(), dx.data() + offsets_[k]);
    } else {
      for (int i = 0; i < b.ambient_size; ++i) dx(offsets_[k] + i) = parameters[k][i] - b.x0[i];
    }
  }
  Eigen::Map<Eigen::VectorXd> r(residuals, J_.rows());
  r = J_ * dx + r0_;
  if (jacobians == nullptr) return true;
  for (std::size_t k = 0; k < blocks_.size(); ++k) {
    if (jacobians[k] == nullptr) continue;
    const PriorBlock& b = blocks_[k];
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Jk(
        jacobians[k], J_.rows(), b.ambient_size);
    if (b.is_pose()) {
      // d(x [-] x0)/dx ~ MinusJacobian at x (exact at x = x0; the prior is linear there anyway).
      Eigen::Matrix<double, 6, 7, Eigen::RowMajor> minus;
      manifold.MinusJacobian(parameters[k], minus.data());
      Jk = J_.middleCols(offsets_[k], 6) * minus;
    } else {
      Jk = J_.middleCols(offsets_[k], b.ambient_size);
    }
  }
  return true;
}

}  // namespace posed::estimator
