#pragma once
// SE(3) helpers shared by the window's camera factors and the loop closer: poses perturbed on the
// right, tangent ordered (rotation, translation) as in the estimator's factors.

#include <Eigen/Geometry>

#include "core/math/so3.hpp"

namespace posed::se3 {

/// Adjoint of T for the (rotation, translation) right perturbation T Exp(ξ) = (R Exp(φ), p + R ρ):
/// T Exp(ξ) T⁻¹ = Exp(Ad(T) ξ).
inline Eigen::Matrix<double, 6, 6> adjoint(const Eigen::Isometry3d& T) {
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  const Eigen::Matrix3d R = T.linear();
  A.topLeftCorner<3, 3>() = R;
  A.bottomLeftCorner<3, 3>() = so3::skew(T.translation()) * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

}  // namespace posed::se3
