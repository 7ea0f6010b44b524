#pragma once
// The seam through which measurements enter the fixed-lag window (small_gicp's factor policies,
// glim's create_factors): a factor is a Ceres cost function together with the parameter blocks it
// touches, in the order its Evaluate expects them. Solve, marginalisation and covariance iterate
// over one list of these; a new sensor adds a factor kind, never a code path in the window.
//
// Parameter blocks are the window's: each state's pose [p (3), q (4)] (perturbed on the
// PoseManifold, tangent 6) and speed_bias [v (3), b_g (3), b_a (3)] (Euclidean, 9). A block is
// named by the state that owns it (its id, stable while the state is in the window) and its role.

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

namespace posed::estimator {

/// What a factor measures; for the status and the counters, the window treats all alike.
enum class FactorKind : std::uint8_t {
  kPrior,          ///< the start-up prior or what marginalisation left behind
  kImu,            ///< preintegrated IMU between consecutive states
  kLidarPose,      ///< a scan-to-map pose of the lidar on one state
  kVisible,        ///< relative motion of the visible camera between two states
  kThermal,        ///< relative motion of the thermal camera between two states
  kFused,          ///< relative motion from the DWT-fused visible+thermal image between two states
  kVehicleMotion,  ///< a wheeled vehicle's velocity along its body x (VehicleMotionFactor)
};
inline constexpr std::size_t kFactorKinds = 7;
inline constexpr std::array<std::string_view, kFactorKinds> kFactorKindNames = {
    "prior", "imu", "lidar_pose", "visible", "thermal", "fused", "vehicle_motion"};
constexpr std::string_view to_string(FactorKind k) {
  return kFactorKindNames[static_cast<std::size_t>(k)];
}

/// Which block of a state.
enum class BlockRole : std::uint8_t {
  kPose,       ///< [p_map_imu (3) [m], q_map_imu (4, x y z w)], tangent [dp (map), dtheta (body)]
  kSpeedBias,  ///< [v_map (3) [m/s], b_g (3) [rad/s], b_a (3) [m/s²]]
  /// the map frame's tilt [a, b] (2) [rad], one block for the whole window (state_id unused);
  /// only when the window estimates it (SlidingWindowConfig::estimate_gravity_tilt)
  kGravityTilt,
};

/// A block by its owner: the state with this id.
struct BlockRef {
  std::uint64_t state_id = 0;
  BlockRole role = BlockRole::kPose;
};

/// A factor in the window: the cost, an optional robust loss, and the blocks (by address) it
/// touches, in the order of the cost function's parameter blocks.
struct WindowFactor {
  FactorKind kind = FactorKind::kPrior;
  std::unique_ptr<ceres::CostFunction> cost;
  std::unique_ptr<ceres::LossFunction> loss;  ///< null: plain least squares
  std::vector<double*> blocks;
};

}  // namespace posed::estimator
