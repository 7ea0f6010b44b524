#pragma once
// SO(3) helpers shared by the estimators: the hat map, exponential and logarithm, and the right
// Jacobian of the exponential (Forster et al. 2017, "On-Manifold Preintegration", eq. 8).
// Rotations use the right perturbation R * Exp(phi) throughout posed.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace posed::so3 {

/// [v]x: skew(v) * w = v.cross(w).
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// Exp(phi) as a unit quaternion; first-order near zero.
inline Eigen::Quaterniond exp_q(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (angle < 1e-10) {
    return Eigen::Quaterniond(1, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z()).normalized();
  }
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, phi / angle));
}

/// Exp(phi) as a rotation matrix.
inline Eigen::Matrix3d exp(const Eigen::Vector3d& phi) { return exp_q(phi).toRotationMatrix(); }

/// Log(q): the rotation vector [rad], angle in [0, pi].
inline Eigen::Vector3d log(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // shortest arc
  const Eigen::Vector3d v = q.vec();
  const double s = v.norm();
  if (s < 1e-10) return 2.0 * v;  // small angle: sin(a/2) ~ a/2
  return 2.0 * std::atan2(s, q.w()) * v / s;
}

/// Log(R).
inline Eigen::Vector3d log(const Eigen::Matrix3d& R) { return log(Eigen::Quaterniond(R)); }

/// Right Jacobian Jr(phi): Exp(phi + d) ~ Exp(phi) Exp(Jr(phi) d).
inline Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (a < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * K;
  const double a2 = a * a;
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(a)) / a2 * K +
         (a - std::sin(a)) / (a2 * a) * K * K;
}

/// Jr(phi)^-1.
inline Eigen::Matrix3d right_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (a < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * K;
  const double a2 = a * a;
  return Eigen::Matrix3d::Identity() + 0.5 * K +
         (1.0 / a2 - (1.0 + std::cos(a)) / (2.0 * a * std::sin(a))) * K * K;
}

}  // namespace posed::so3
