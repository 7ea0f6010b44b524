#pragma once
// Seed 001's adaptive pose selection (§ 2.3, eq. 10-12): which odometry gives the back end its
// initial value for a new state. Over the period Δt since the previous state:
//   S     = the IMU's own displacement over the period, (1/η) Σ V(t_K) (eq. 10): the dynamic
//           threshold, which grows with speed (the paper seeds V0 with the previous period's mean
//           velocity, i.e. the last optimised state's, as we do);
//   H_x   = |Δp_x - Δp_imu| (eq. 11-12) for x = lci (lidar-visual-inertial), lio (lidar-inertial),
//           cio (visual-inertial): how far each odometry's displacement is from the IMU's.
// Rule: H_lci < S → LCI. Otherwise the smallest of H_lio, H_cio decides, unless H_lci is smaller
// still: LIO if H_lio < H_cio and H_lio < H_lci; CIO if H_cio < H_lio and H_cio < H_lci; else LCI.
//
// posed's odometries for one state: LIO is the scan-to-map pose, CIO the previous state carried by
// the cameras' frame-to-frame motion, LCI their combination with the IMU prediction, each
// position weighed by its information (a degenerate scan contributes nothing along its
// degenerate directions). When a modality is missing the choice is between what remains.

#include <Eigen/Core>
#include <cstdint>
#include <optional>

namespace posed::estimator {

enum class PoseChoice : std::uint8_t {
  kImu,                  ///< nothing else to choose from: the IMU prediction
  kLidarInertial,        ///< LIO
  kVisualInertial,       ///< CIO
  kLidarVisualInertial,  ///< LCI
};

/// Displacements over the period, in the map frame [m].
struct PoseSelectionInput {
  double threshold_m = 0;              ///< S [m]
  Eigen::Vector3d imu;                 ///< Δp of the IMU prediction [m]
  std::optional<Eigen::Vector3d> lio;  ///< Δp of the scan match [m]
  std::optional<Eigen::Vector3d> cio;  ///< Δp of the camera motion [m]
  std::optional<Eigen::Vector3d> lci;  ///< Δp of the combination [m]
};

PoseChoice select_pose(const PoseSelectionInput& in);

/// A position and its information [1/m²], for combine().
struct WeightedPosition {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
};

/// The information-weighted mean of the positions (their combined Gaussian); nullopt when the
/// summed information is singular.
std::optional<Eigen::Vector3d> combine(const WeightedPosition* positions, std::size_t count);

}  // namespace posed::estimator
