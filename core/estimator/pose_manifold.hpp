#pragma once
// The manifold of a pose parameter block [p_x p_y p_z q_x q_y q_z q_w] (position in map, Eigen's
// quaternion order) for Ceres: tangent [dp (map frame), dtheta (body frame, right perturbation
// q * Exp(dtheta))], the convention of the rest of posed. Ceres's own quaternion manifolds
// perturb on the left and in half-angles, which would make the marginalisation prior and the
// published covariances speak another convention.

#include <ceres/manifold.h>

#include <Eigen/Geometry>

#include "core/math/so3.hpp"

namespace posed::estimator {

class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }

  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    Eigen::Map<const Eigen::Vector3d> p(x);
    Eigen::Map<const Eigen::Quaterniond> q(x + 3);
    Eigen::Map<const Eigen::Vector3d> dp(delta), dtheta(delta + 3);
    Eigen::Map<Eigen::Vector3d> p_out(x_plus_delta);
    Eigen::Map<Eigen::Quaterniond> q_out(x_plus_delta + 3);
    p_out = p + dp;
    q_out = (q * so3::exp_q(dtheta)).normalized();
    return true;
  }

  bool PlusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
    const Eigen::Vector3d qv(x[3], x[4], x[5]);
    const double qw = x[6];
    J.setZero();
    J.topLeftCorner<3, 3>().setIdentity();
    // d(q * [dtheta/2, 1]) / d(dtheta) at 0: vector part 0.5 (qw I + [qv]x), scalar -0.5 qvᵀ.
    J.block<3, 3>(3, 3) = 0.5 * (qw * Eigen::Matrix3d::Identity() + so3::skew(qv));
    J.block<1, 3>(6, 3) = -0.5 * qv.transpose();
    return true;
  }

  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Eigen::Map<const Eigen::Vector3d> py(y), px(x);
    Eigen::Map<const Eigen::Quaterniond> qy(y + 3), qx(x + 3);
    Eigen::Map<Eigen::Vector3d> dp(y_minus_x), dtheta(y_minus_x + 3);
    dp = py - px;
    dtheta = so3::log(Eigen::Quaterniond(qx.conjugate() * qy));
    return true;
  }

  bool MinusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
    const Eigen::Vector3d qv(x[3], x[4], x[5]);
    const double qw = x[6];
    J.setZero();
    J.topLeftCorner<3, 3>().setIdentity();
    // d(2 vec(x^-1 * y)) / dy at y = x: 2 [qw I - [qv]x, -qv].
    J.block<3, 3>(3, 3) = 2.0 * (qw * Eigen::Matrix3d::Identity() - so3::skew(qv));
    J.block<3, 1>(3, 6) = -2.0 * qv;
    return true;
  }
};

}  // namespace posed::estimator
