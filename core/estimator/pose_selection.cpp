#include "core/estimator/pose_selection.hpp"

#include <Eigen/Cholesky>

namespace posed::estimator {

PoseChoice select_pose(const PoseSelectionInput& in) {
  const auto H = [&](const std::optional<Eigen::Vector3d>& d) {
    return d ? std::optional<double>((*d - in.imu).norm()) : std::nullopt;
  };
  const std::optional<double> h_lci = H(in.lci), h_lio = H(in.lio), h_cio = H(in.cio);
  if (h_lio && h_cio && h_lci) {
    if (*h_lci < in.threshold_m) return PoseChoice::kLidarVisualInertial;
    if (*h_lio < *h_cio && *h_lio < *h_lci) return PoseChoice::kLidarInertial;
    if (*h_cio < *h_lio && *h_cio < *h_lci) return PoseChoice::kVisualInertial;
    return PoseChoice::kLidarVisualInertial;
  }
  // One odometry besides the IMU: nothing to compare it with, it is taken.
  if (h_lio) return PoseChoice::kLidarInertial;
  if (h_cio) return PoseChoice::kVisualInertial;
  return PoseChoice::kImu;
}

std::optional<Eigen::Vector3d> combine(const WeightedPosition* positions, std::size_t count) {
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < count; ++k) {
    I += positions[k].information;
    b += positions[k].information * positions[k].p;
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(I);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || ldlt.vectorD().minCoeff() <= 0) {
    return std::nullopt;
  }
  return ldlt.solve(b);
}

}  // namespace posed::estimator
