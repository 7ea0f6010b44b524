#include "core/estimator/linearisation.hpp"

#include <cmath>
#include <vector>

#include "core/estimator/pose_manifold.hpp"

namespace posed::estimator {

void TangentLayout::add(const double* block, int ambient_size) {
  if (slots.count(block) != 0) return;
  Slot s;
  s.offset = size;
  s.ambient_size = ambient_size;
  s.tangent_size = ambient_size == 7 ? 6 : ambient_size;
  slots.emplace(block, s);
  size += s.tangent_size;
}

const TangentLayout::Slot* TangentLayout::find(const double* block) const {
  const auto it = slots.find(block);
  return it == slots.end() ? nullptr : &it->second;
}

bool accumulate(const WindowFactor& factor, const TangentLayout& layout, Eigen::MatrixXd& H,
                Eigen::VectorXd* b) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const ceres::CostFunction& cost = *factor.cost;
  const int m = cost.num_residuals();
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  const std::size_t n = factor.blocks.size();
  Eigen::VectorXd r(m);
  std::vector<RowMajor> J_ambient(n);
  std::vector<double*> jac_ptrs(n, nullptr);
  std::vector<const TangentLayout::Slot*> slot(n);
  for (std::size_t k = 0; k < n; ++k) {
    slot[k] = layout.find(factor.blocks[k]);
    if (slot[k] == nullptr) continue;  // a constant here
    J_ambient[k].resize(m, sizes[k]);
    jac_ptrs[k] = J_ambient[k].data();
  }
  std::vector<const double*> params(factor.blocks.begin(), factor.blocks.end());
  if (!cost.Evaluate(params.data(), r.data(), jac_ptrs.data())) return false;

  double weight = 1.0;
  if (factor.loss) {
    double rho[3];
    factor.loss->Evaluate(r.squaredNorm(), rho);
    weight = std::sqrt(std::max(rho[1], 0.0));
  }
  // Tangent Jacobians: a pose's ambient Jacobian times the manifold's PlusJacobian.
  static const PoseManifold manifold;
  std::vector<Eigen::MatrixXd> J(n);
  for (std::size_t k = 0; k < n; ++k) {
    if (slot[k] == nullptr) continue;
    if (slot[k]->is_pose()) {
      Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus;
      manifold.PlusJacobian(factor.blocks[k], plus.data());
      J[k] = weight * (J_ambient[k] * plus);
    } else {
      J[k] = weight * J_ambient[k];
    }
  }
  r *= weight;
  for (std::size_t a = 0; a < n; ++a) {
    if (slot[a] == nullptr) continue;
    const int oa = slot[a]->offset, ta = slot[a]->tangent_size;
    if (b != nullptr) b->segment(oa, ta) += J[a].transpose() * r;
    for (std::size_t c = 0; c < n; ++c) {
      if (slot[c] == nullptr) continue;
      H.block(oa, slot[c]->offset, ta, slot[c]->tangent_size) += J[a].transpose() * J[c];
    }
  }
  return true;
}

}  // namespace posed::estimator
