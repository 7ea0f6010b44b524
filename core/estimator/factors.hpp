#pragma once
// The residuals of the lidar-inertial sliding window, as Ceres cost functions with analytic
// Jacobians (autodiff of the 15x32 IMU factor cost a minute of compile time per build on two
// cores, and time per solve). Parameter blocks:
//   pose        [p (3, map), q (4, Eigen x y z w)]: the IMU (base_link) in map
//   speed_bias  [v (3, map) [m/s], b_g (3) [rad/s], b_a (3) [m/s²]]
// Jacobians are derived in the pose manifold's tangent space [dp (map), dtheta (body, right)] and
// returned in ambient coordinates as J_tangent * MinusJacobian(x) (PoseManifold), whose product
// with PlusJacobian is J_tangent again. Residuals are whitened by the square-root information.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/imu/preintegration.hpp"

namespace posed::estimator {

/// Preintegrated IMU between states i and j (Forster eq. 45) and the bias random walk:
/// 15 residuals [rotation, velocity, position, gyro bias change, accel bias change].
/// With `with_gravity_tilt`, a fifth block [a, b] (2) [rad] tilts gravity in the map frame:
/// g_map = Exp([a, b, 0]) (0, 0, -g). The map frame is the first scan's, levelled only as well as
/// the start-up alignment could; estimated, its tilt's share of gravity no longer has to hide in
/// the accelerometer bias (docs/estimator.md, Known limits).
class ImuFactor final : public ceres::CostFunction {
 public:
  /// Weighed by the preintegration's covariance and its biases' random walk.
  ImuFactor(const imu::Preintegration& pre, double gravity_mps2, bool with_gravity_tilt = false);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  imu::Preintegration pre_;
  Eigen::Vector3d g_;
  bool with_gravity_tilt_;
  Eigen::Matrix<double, 15, 15> sqrt_info_;
};

/// Gravity in the map frame for a tilt [a, b] of it (ImuFactor's fifth block) [m/s²], and its
/// Jacobian with respect to [a, b] when `d_dtilt` is given.
Eigen::Vector3d tilted_gravity(double gravity_mps2, const double* tilt,
                               Eigen::Matrix<double, 3, 2>* d_dtilt = nullptr);

/// A scan-to-map pose of the lidar, with its information (rotation, translation; right
/// perturbation), on the IMU pose through T_imu_lidar: 6 residuals [rotation, translation].
class LidarPoseFactor final : public ceres::SizedCostFunction<6, 7> {
 public:
  LidarPoseFactor(const Eigen::Isometry3d& T_map_lidar, const Eigen::Isometry3d& T_imu_lidar,
                  const Eigen::Matrix<double, 6, 6>& information);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d p_meas_;
  Eigen::Matrix3d R_meas_;
  Eigen::Vector3d p_il_;
  Eigen::Matrix3d R_il_;
  Eigen::Matrix<double, 6, 6> sqrt_info_;
};

/// A relative motion of the IMU (base_link) from state i to state j, T_i_j = T_map_i⁻¹ T_map_j,
/// measured by another sensor (a camera's frame-to-frame motion carried over to the IMU frame),
/// with its information in the same right-perturbation (rotation, translation) convention:
/// 6 residuals r = [Log(R_meas⁻¹ R_i⁻¹ R_j), R_meas⁻¹ (R_i⁻¹ (p_j - p_i) - p_meas)] (seed 002's
/// VIO/TIO "between" factor).
class RelativePoseFactor final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  RelativePoseFactor(const Eigen::Isometry3d& T_i_j,
                     const Eigen::Matrix<double, 6, 6>& information);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Matrix3d R_meas_;
  Eigen::Vector3d p_meas_;
  Eigen::Matrix<double, 6, 6> sqrt_info_;
};

/// A landmark seen by a camera from two states (LVI-SAM's VIS, VINS-Mono's projection factor with
/// the depth held at the lidar's): the point X_a, fixed in the body frame of anchor state a where
/// it was first seen with lidar depth, must project onto its observation in a later frame of
/// state j. 2 residuals, the normalised image coordinates' error times `sqrt_information`
/// (focal length over pixel sigma): r = s ((x, y) / z - u) with (x, y, z) = T_body_cam⁻¹
/// T_map_j⁻¹ T_map_a X_a. T_body_cam is the camera of the observing frame in state j's body
/// (the extrinsic, and the short bridge from the frame's stamp to the state's).
class LandmarkFactor final : public ceres::SizedCostFunction<2, 7, 7> {
 public:
  LandmarkFactor(const Eigen::Vector3d& X_a, const Eigen::Isometry3d& T_body_cam,
                 const Eigen::Vector2d& observed_normalised, double sqrt_information);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  /// The landmark in the observing camera at poses a and j (for checks before a factor is added).
  Eigen::Vector3d point_in_camera(const Eigen::Isometry3d& T_map_a,
                                  const Eigen::Isometry3d& T_map_j) const;

 private:
  Eigen::Vector3d X_a_;
  Eigen::Matrix3d R_bc_T_;
  Eigen::Vector3d t_bc_;
  Eigen::Vector2d observed_;
  double sqrt_information_;
};

/// A wheeled or tracked vehicle's motion: the point of the body that rolls without slipping
/// (`c_base_m`, the middle of a differential drive's axle) moves along the body's x, neither
/// sideways nor up. 2 residuals [y, z] of that point's velocity in base_link, v_c = Rᵀ v + ω × c,
/// over `sigma_mps` (wheel slip, bumps, a slope's change). ω (body, gyro less its bias at the
/// state) is a constant of the factor. Blocks: the state's pose (7) and speed_bias (9).
/// Along a corridor or a roadway, where the lidar pins the motion across the axis but not along
/// it, this ties the speed along the axis to the pinned sideways speed whenever the heading is
/// off the axis (a swerve, a U-turn): v_x = v_y / tan(heading).
class VehicleMotionFactor final : public ceres::SizedCostFunction<2, 7, 9> {
 public:
  VehicleMotionFactor(const Eigen::Vector3d& w_base_radps, const Eigen::Vector3d& c_base_m,
                      double sigma_lateral_mps, double sigma_vertical_mps);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d w_cross_c_;  // ω × c [m/s]
  Eigen::Vector2d inv_sigma_;
};

/// The square root of a (possibly singular) information matrix: S with Sᵀ S = information.
Eigen::Matrix<double, 6, 6> sqrt_information(const Eigen::Matrix<double, 6, 6>& information);

}  // namespace posed::estimator
