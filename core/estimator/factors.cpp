#include "core/estimator/factors.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>

#include "core/estimator/pose_manifold.hpp"
#include "core/math/so3.hpp"

namespace posed::estimator {
namespace {

using so3::skew;
using Mat3 = Eigen::Matrix3d;

/// Writes J_tangent (m x 6) as the ambient m x 7 Jacobian of a pose block.
template <int M>
void pose_jacobian(const Eigen::Matrix<double, M, 6>& J_tangent, const double* pose, double* out) {
  Eigen::Matrix<double, 6, 7, Eigen::RowMajor> minus;
  PoseManifold().MinusJacobian(pose, minus.data());
  Eigen::Map<Eigen::Matrix<double, M, 7, Eigen::RowMajor>> J(out);
  J = J_tangent * minus;
}

}  // namespace

Eigen::Vector3d tilted_gravity(double gravity_mps2, const double* tilt,
                               Eigen::Matrix<double, 3, 2>* d_dtilt) {
  const Eigen::Vector3d phi(tilt[0], tilt[1], 0.0);
  const Eigen::Vector3d g0(0, 0, -gravity_mps2);
  const Mat3 R = so3::exp(phi);
  if (d_dtilt != nullptr) {
    // d(Exp(phi) g0)/dphi = -Exp(phi) [g0]x Jr(phi); only phi's x and y are free.
    *d_dtilt = (-R * skew(g0) * so3::right_jacobian(phi)).leftCols<2>();
  }
  return R * g0;
}

ImuFactor::ImuFactor(const imu::Preintegration& pre, double gravity_mps2, bool with_gravity_tilt)
    : pre_(pre), g_(0, 0, -gravity_mps2), with_gravity_tilt_(with_gravity_tilt) {
  set_num_residuals(15);
  *mutable_parameter_block_sizes() = {7, 9, 7, 9};
  if (with_gravity_tilt_) mutable_parameter_block_sizes()->push_back(2);
  Eigen::Matrix<double, 15, 15> cov = Eigen::Matrix<double, 15, 15>::Zero();
  cov.topLeftCorner<9, 9>() = pre.covariance();
  cov.block<3, 3>(9, 9).diagonal().setConstant(pre.gyro_bias_walk_variance());
  cov.block<3, 3>(12, 12).diagonal().setConstant(pre.accel_bias_walk_variance());
  // A floor keeps the information finite for very short intervals and noise-free tests.
  cov += 1e-12 * Eigen::Matrix<double, 15, 15>::Identity();
  sqrt_info_ = Eigen::LLT<Eigen::Matrix<double, 15, 15>>(cov.inverse()).matrixL().transpose();
}

bool ImuFactor::Evaluate(double const* const* parameters, double* residuals,
                         double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> pi(parameters[0]), pj(parameters[2]);
  const Eigen::Map<const Eigen::Quaterniond> qi(parameters[0] + 3), qj(parameters[2] + 3);
  const Eigen::Map<const Eigen::Vector3d> vi(parameters[1]), bgi(parameters[1] + 3),
      bai(parameters[1] + 6);
  const Eigen::Map<const Eigen::Vector3d> vj(parameters[3]), bgj(parameters[3] + 3),
      baj(parameters[3] + 6);
  const Mat3 Ri = qi.normalized().toRotationMatrix(), Rj = qj.normalized().toRotationMatrix();
  const Mat3 Ri_T = Ri.transpose();
  const imu::ImuBias& lin = pre_.linearisation_bias();
  const Eigen::Vector3d dbg = bgi - lin.gyro_radps;
  const double dt = pre_.dt_s();

  Eigen::Matrix<double, 3, 2> dg_dtilt = Eigen::Matrix<double, 3, 2>::Zero();
  const Eigen::Vector3d g =
      with_gravity_tilt_ ? tilted_gravity(-g_.z(), parameters[4], &dg_dtilt) : g_;
  const Mat3 Rc = pre_.corrected_delta_R(bgi);
  const Mat3 E = Rc.transpose() * Ri_T * Rj;
  const Eigen::Vector3d r_R = so3::log(E);
  const Eigen::Vector3d dv_world = vj - vi - g * dt;
  const Eigen::Vector3d dp_world = pj - pi - vi * dt - 0.5 * g * dt * dt;
  Eigen::Matrix<double, 15, 1> r;
  r.segment<3>(0) = r_R;
  r.segment<3>(3) = Ri_T * dv_world - pre_.corrected_delta_v(bgi, bai);
  r.segment<3>(6) = Ri_T * dp_world - pre_.corrected_delta_p(bgi, bai);
  r.segment<3>(9) = bgj - bgi;
  r.segment<3>(12) = baj - bai;
  Eigen::Map<Eigen::Matrix<double, 15, 1>> out(residuals);
  out = sqrt_info_ * r;
  if (jacobians == nullptr) return true;

  const Mat3 Jr_inv = so3::right_jacobian_inverse(r_R);
  if (jacobians[0] != nullptr) {  // pose i: [dp, dtheta]
    Eigen::Matrix<double, 15, 6> J = Eigen::Matrix<double, 15, 6>::Zero();
    J.block<3, 3>(0, 3) = -Jr_inv * Rj.transpose() * Ri;
    J.block<3, 3>(3, 3) = skew(Ri_T * dv_world);
    J.block<3, 3>(6, 0) = -Ri_T;
    J.block<3, 3>(6, 3) = skew(Ri_T * dp_world);
    pose_jacobian<15>(sqrt_info_ * J, parameters[0], jacobians[0]);
  }
  if (jacobians[1] != nullptr) {  // speed-bias i: [v, b_g, b_a]
    Eigen::Matrix<double, 15, 9> J = Eigen::Matrix<double, 15, 9>::Zero();
    const Mat3 J_bg = pre_.dR_dbg();
    J.block<3, 3>(0, 3) = -Jr_inv * E.transpose() * so3::right_jacobian(J_bg * dbg) * J_bg;
    J.block<3, 3>(3, 0) = -Ri_T;
    J.block<3, 3>(3, 3) = -pre_.dv_dbg();
    J.block<3, 3>(3, 6) = -pre_.dv_dba();
    J.block<3, 3>(6, 0) = -Ri_T * dt;
    J.block<3, 3>(6, 3) = -pre_.dp_dbg();
    J.block<3, 3>(6, 6) = -pre_.dp_dba();
    J.block<3, 3>(9, 3) = -Mat3::Identity();
    J.block<3, 3>(12, 6) = -Mat3::Identity();
    Eigen::Map<Eigen::Matrix<double, 15, 9, Eigen::RowMajor>> Jm(jacobians[1]);
    Jm = sqrt_info_ * J;
  }
  if (jacobians[2] != nullptr) {  // pose j
    Eigen::Matrix<double, 15, 6> J = Eigen::Matrix<double, 15, 6>::Zero();
    J.block<3, 3>(0, 3) = Jr_inv;
    J.block<3, 3>(6, 0) = Ri_T;
    pose_jacobian<15>(sqrt_info_ * J, parameters[2], jacobians[2]);
  }
  if (jacobians[3] != nullptr) {  // speed-bias j
    Eigen::Matrix<double, 15, 9> J = Eigen::Matrix<double, 15, 9>::Zero();
    J.block<3, 3>(3, 0) = Ri_T;
    J.block<3, 3>(9, 3) = Mat3::Identity();
    J.block<3, 3>(12, 6) = Mat3::Identity();
    Eigen::Map<Eigen::Matrix<double, 15, 9, Eigen::RowMajor>> Jm(jacobians[3]);
    Jm = sqrt_info_ * J;
  }
  if (with_gravity_tilt_ && jacobians[4] != nullptr) {  // gravity tilt [a, b]
    Eigen::Matrix<double, 15, 2> J = Eigen::Matrix<double, 15, 2>::Zero();
    J.block<3, 2>(3, 0) = -Ri_T * dg_dtilt * dt;
    J.block<3, 2>(6, 0) = -0.5 * Ri_T * dg_dtilt * dt * dt;
    Eigen::Map<Eigen::Matrix<double, 15, 2, Eigen::RowMajor>> Jm(jacobians[4]);
    Jm = sqrt_info_ * J;
  }
  return true;
}

LidarPoseFactor::LidarPoseFactor(const Eigen::Isometry3d& T_map_lidar,
                                 const Eigen::Isometry3d& T_imu_lidar,
                                 const Eigen::Matrix<double, 6, 6>& information)
    : p_meas_(T_map_lidar.translation()),
      R_meas_(T_map_lidar.linear()),
      p_il_(T_imu_lidar.translation()),
      R_il_(T_imu_lidar.linear()) {
  sqrt_info_ = sqrt_information(information);
}

Eigen::Matrix<double, 6, 6> sqrt_information(const Eigen::Matrix<double, 6, 6>& information) {
  // information = V diag(l) Vᵀ, possibly singular: sqrt = diag(sqrt(l)) Vᵀ.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(
      0.5 * (information + information.transpose()));
  return es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() * es.eigenvectors().transpose();
}

bool LidarPoseFactor::Evaluate(double const* const* parameters, double* residuals,
                               double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> p(parameters[0]);
  const Mat3 R =
      Eigen::Map<const Eigen::Quaterniond>(parameters[0] + 3).normalized().toRotationMatrix();
  const Mat3 R_meas_T = R_meas_.transpose();
  const Eigen::Vector3d r_rot = so3::log(Mat3(R_meas_T * R * R_il_));
  Eigen::Matrix<double, 6, 1> r;
  r.head<3>() = r_rot;
  r.tail<3>() = R_meas_T * (p + R * p_il_ - p_meas_);
  Eigen::Map<Eigen::Matrix<double, 6, 1>> out(residuals);
  out = sqrt_info_ * r;
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Zero();
    J.block<3, 3>(0, 3) = so3::right_jacobian_inverse(r_rot) * R_il_.transpose();
    J.block<3, 3>(3, 0) = R_meas_T;
    J.block<3, 3>(3, 3) = -R_meas_T * R * skew(p_il_);
    pose_jacobian<6>(sqrt_info_ * J, parameters[0], jacobians[0]);
  }
  return true;
}

VehicleMotionFactor::VehicleMotionFactor(const Eigen::Vector3d& w_base_radps,
                                         const Eigen::Vector3d& c_base_m, double sigma_lateral_mps,
                                         double sigma_vertical_mps)
    : w_cross_c_(w_base_radps.cross(c_base_m)),
      inv_sigma_(1.0 / sigma_lateral_mps, 1.0 / sigma_vertical_mps) {}

bool VehicleMotionFactor::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const Mat3 R =
      Eigen::Map<const Eigen::Quaterniond>(parameters[0] + 3).normalized().toRotationMatrix();
  const Eigen::Map<const Eigen::Vector3d> v(parameters[1]);
  const Eigen::Vector3d v_body = R.transpose() * v;
  const Eigen::Vector3d v_c = v_body + w_cross_c_;
  residuals[0] = v_c.y() * inv_sigma_.x();
  residuals[1] = v_c.z() * inv_sigma_.y();
  if (jacobians == nullptr) return true;
  const Eigen::Matrix<double, 2, 3> S =
      inv_sigma_.asDiagonal() * Eigen::Matrix3d::Identity().bottomRows<2>();
  if (jacobians[0] != nullptr) {
    // R Exp(dθ): Rᵀ v -> (I - [dθ]x) Rᵀ v = Rᵀ v + [Rᵀ v]x dθ.
    Eigen::Matrix<double, 2, 6> J = Eigen::Matrix<double, 2, 6>::Zero();
    J.rightCols<3>() = S * skew(v_body);
    pose_jacobian<2>(J, parameters[0], jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 9, Eigen::RowMajor>> J(jacobians[1]);
    J.setZero();
    J.leftCols<3>() = S * R.transpose();
  }
  return true;
}

RelativePoseFactor::RelativePoseFactor(const Eigen::Isometry3d& T_i_j,
                                       const Eigen::Matrix<double, 6, 6>& information)
    : R_meas_(T_i_j.linear()),
      p_meas_(T_i_j.translation()),
      sqrt_info_(sqrt_information(information)) {}

bool RelativePoseFactor::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> pi(parameters[0]), pj(parameters[1]);
  const Mat3 Ri =
      Eigen::Map<const Eigen::Quaterniond>(parameters[0] + 3).normalized().toRotationMatrix();
  const Mat3 Rj =
      Eigen::Map<const Eigen::Quaterniond>(parameters[1] + 3).normalized().toRotationMatrix();
  const Mat3 Rm_T = R_meas_.transpose();
  const Eigen::Vector3d d_i = Ri.transpose() * (pj - pi);  // p_j in frame i
  const Eigen::Vector3d r_rot = so3::log(Mat3(Rm_T * Ri.transpose() * Rj));
  Eigen::Matrix<double, 6, 1> r;
  r.head<3>() = r_rot;
  r.tail<3>() = Rm_T * (d_i - p_meas_);
  Eigen::Map<Eigen::Matrix<double, 6, 1>> out(residuals);
  out = sqrt_info_ * r;
  if (jacobians == nullptr) return true;
  const Mat3 Jr_inv = so3::right_jacobian_inverse(r_rot);
  if (jacobians[0] != nullptr) {  // pose i: R_i Exp(d) turns Ri⁻¹ Rj into Exp(-d) Ri⁻¹ Rj
    Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Zero();
    J.block<3, 3>(0, 3) = -Jr_inv * Rj.transpose() * Ri;
    J.block<3, 3>(3, 0) = -Rm_T * Ri.transpose();
    J.block<3, 3>(3, 3) = Rm_T * skew(d_i);
    pose_jacobian<6>(sqrt_info_ * J, parameters[0], jacobians[0]);
  }
  if (jacobians[1] != nullptr) {  // pose j
    Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Zero();
    J.block<3, 3>(0, 3) = Jr_inv;
    J.block<3, 3>(3, 0) = Rm_T * Ri.transpose();
    pose_jacobian<6>(sqrt_info_ * J, parameters[1], jacobians[1]);
  }
  return true;
}

LandmarkFactor::LandmarkFactor(const Eigen::Vector3d& X_a, const Eigen::Isometry3d& T_body_cam,
                               const Eigen::Vector2d& observed_normalised, double sqrt_information)
    : X_a_(X_a),
      R_bc_T_(T_body_cam.linear().transpose()),
      t_bc_(T_body_cam.translation()),
      observed_(observed_normalised),
      sqrt_information_(sqrt_information) {}

Eigen::Vector3d LandmarkFactor::point_in_camera(const Eigen::Isometry3d& T_map_a,
                                                const Eigen::Isometry3d& T_map_j) const {
  const Eigen::Vector3d P_j = T_map_j.inverse() * (T_map_a * X_a_);
  return R_bc_T_ * (P_j - t_bc_);
}

bool LandmarkFactor::Evaluate(double const* const* parameters, double* residuals,
                              double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> pa(parameters[0]), pj(parameters[1]);
  const Mat3 Ra =
      Eigen::Map<const Eigen::Quaterniond>(parameters[0] + 3).normalized().toRotationMatrix();
  const Mat3 Rj =
      Eigen::Map<const Eigen::Quaterniond>(parameters[1] + 3).normalized().toRotationMatrix();
  const Eigen::Vector3d P_map = Ra * X_a_ + pa;
  const Eigen::Vector3d P_j = Rj.transpose() * (P_map - pj);  // in state j's body
  const Eigen::Vector3d P_c = R_bc_T_ * (P_j - t_bc_);        // in the observing camera
  // Behind (or at) the camera: a large constant residual, no gradient (Huber caps its weight).
  if (P_c.z() < 1e-3) {
    residuals[0] = residuals[1] = sqrt_information_;
    for (int k = 0; k < 2; ++k) {
      if (jacobians != nullptr && jacobians[k] != nullptr) std::fill_n(jacobians[k], 14, 0.0);
    }
    return true;
  }
  const double inv_z = 1.0 / P_c.z();
  Eigen::Map<Eigen::Vector2d> r(residuals);
  r = sqrt_information_ * (P_c.head<2>() * inv_z - observed_);
  if (jacobians == nullptr) return true;
  Eigen::Matrix<double, 2, 3> d_proj;
  d_proj << inv_z, 0, -P_c.x() * inv_z * inv_z, 0, inv_z, -P_c.y() * inv_z * inv_z;
  const Eigen::Matrix<double, 2, 3> d_Pj = sqrt_information_ * d_proj * R_bc_T_;
  if (jacobians[0] != nullptr) {  // pose a: dP_map = dp + Ra (dtheta x X_a)
    Eigen::Matrix<double, 2, 6> J;
    const Eigen::Matrix<double, 2, 3> d_Pmap = d_Pj * Rj.transpose();
    J.leftCols<3>() = d_Pmap;
    J.rightCols<3>() = -d_Pmap * Ra * skew(X_a_);
    pose_jacobian<2>(J, parameters[0], jacobians[0]);
  }
  if (jacobians[1] != nullptr) {  // pose j: dP_j = -Rjᵀ dp + skew(P_j) dtheta
    Eigen::Matrix<double, 2, 6> J;
    J.leftCols<3>() = -d_Pj * Rj.transpose();
    J.rightCols<3>() = d_Pj * skew(P_j);
    pose_jacobian<2>(J, parameters[1], jacobians[1]);
  }
  return true;
}

}  // namespace posed::estimator
