#pragma once
// The body's rotation between two instants from the gyro alone: what the camera front end needs
// to warp a thermal frame to its visible partner's stamp (issue 9, pairing: the paper pairs
// without compensation; we compensate). Over the 0-20 ms between partners the gyro is far
// better than any pose estimate, and needs no estimator state beyond the bias.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/sync/imu_buffer.hpp"
#include "core/time.hpp"

namespace posed::fusion {

/// R_b0_b1: the body frame at `t1` expressed in the body frame at `t0` (p_b0 = R_b0_b1 p_b1), by
/// midpoint integration of the bias-corrected rate between the samples, interpolated at t0 and
/// t1. Works for t1 < t0 too (the inverse). nullopt when the buffer does not cover both instants.
/// `scratch` is reused between calls.
std::optional<Eigen::Matrix3d> gyro_rotation(const ImuBuffer& imu, HostTime t0, HostTime t1,
                                             const Eigen::Vector3d& gyro_bias_radps,
                                             std::vector<ImuSample>& scratch);

}  // namespace posed::fusion
