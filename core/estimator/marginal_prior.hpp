#pragma once
// A linear Gaussian prior on any set of window blocks, r = J (x [-] x0) + r0, with x [-] x0 taken
// block by block in the tangent spaces (poses on the PoseManifold, the rest Euclidean): the
// start-up prior on the first state, and what marginalisation leaves behind on every block that
// shared a factor with the states it dropped (VINS-Mono's MarginalizationFactor).

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <vector>

namespace posed::estimator {

/// One block of the prior: its ambient size (7 for a pose, which is then perturbed on the
/// PoseManifold; anything else is Euclidean) and its value at linearisation.
struct PriorBlock {
  int ambient_size = 0;
  std::vector<double> x0;
  bool is_pose() const { return ambient_size == 7; }
  int tangent_size() const { return is_pose() ? 6 : ambient_size; }
};

class MarginalPrior final : public ceres::CostFunction {
 public:
  /// `J` has one column per tangent coordinate of `blocks`, in their order; `r0` as many rows
  /// as J.
  MarginalPrior(std::vector<PriorBlock> blocks, const Eigen::MatrixXd& J,
                const Eigen::VectorXd& r0);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  const std::vector<PriorBlock>& blocks() const { return blocks_; }

 private:
  std::vector<PriorBlock> blocks_;
  std::vector<int> offsets_;  ///< tangent column of each block in J
  Eigen::MatrixXd J_;
  Eigen::VectorXd r0_;
};

}  // namespace posed::estimator
