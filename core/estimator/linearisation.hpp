#pragma once
// Gauss-Newton normal equations of window factors in the blocks' tangent spaces: what
// marginalisation (Schur complement) and the published covariance are computed from. One
// function for both, so they cannot disagree about how a factor is linearised.

#include <Eigen/Core>
#include <unordered_map>

#include "core/estimator/window_factor.hpp"

namespace posed::estimator {

/// Where each block's tangent coordinates sit in H and b, and how big the tangent is.
struct TangentLayout {
  struct Slot {
    int offset = 0;
    int tangent_size = 0;
    int ambient_size = 0;
    bool is_pose() const { return ambient_size == 7; }
  };
  std::unordered_map<const double*, Slot> slots;
  int size = 0;  ///< total tangent dimension

  /// Appends a block (no-op if present): a pose when ambient 7, else Euclidean.
  void add(const double* block, int ambient_size);
  const Slot* find(const double* block) const;
};

/// Adds the factor's JᵀJ and Jᵀr at the blocks' current values to H and b (b may be null).
/// Blocks not in `layout` are treated as constants. A robust loss weighs the factor by
/// sqrt(rho'(|r|²)) (the first-order part of Triggs' correction). Returns false when the
/// cost function fails to evaluate.
bool accumulate(const WindowFactor& factor, const TangentLayout& layout, Eigen::MatrixXd& H,
                Eigen::VectorXd* b);

}  // namespace posed::estimator
