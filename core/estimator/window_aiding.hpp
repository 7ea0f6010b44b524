#pragma once
// What another sensor hands the lidar-inertial window for each new state: relative motions of
// base_link since the previous state, as seed 002's loosely coupled VIO/TIO "between" factors.
// The camera back end (core/fusion/camera_factors) implements it; LioEstimator asks it once per
// scan, before the new state joins the window, so the measurements can also take part in
// choosing the state's initial value (seed 001's adaptive pose selection).

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "core/estimator/sliding_window.hpp"
#include "core/estimator/window_factor.hpp"
#include "core/imu/preintegration.hpp"

namespace posed::estimator {

/// A motion of base_link ending at the new state j: T_k_j = T_map_k⁻¹ T_map_j from a state k of
/// the window (the newest, i, for a consecutive pair; an older keyframe for a longer baseline).
struct RelativeMotion {
  FactorKind kind = FactorKind::kVisible;
  /// k: the window index (at the time of the call) of the state the motion starts from
  std::size_t from_index = 0;
  Eigen::Isometry3d T_k_j = Eigen::Isometry3d::Identity();
  /// the same motion from the newest state i, through the window's current estimate of k to i
  /// (T_i_j = T_map_i⁻¹ T_map_k T_k_j), for the checks that compare sensors over the interval
  Eigen::Isometry3d T_i_j = Eigen::Isometry3d::Identity();
  /// (rotation, translation), right perturbation of T_k_j (and so of T_i_j)
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
  /// robust loss scale in whitened units (Huber); 0: plain least squares
  double huber_sigma = 0;
};

class WindowAiding {
 public:
  virtual ~WindowAiding() = default;
  /// Appends the relative motions measured between states of the window (optimised) and the
  /// state about to be added at `next.stamp`, whose pose `next` is its IMU prediction. May
  /// append nothing.
  virtual void relative_motions(const SlidingWindow& window, const imu::ImuState& next,
                                std::vector<RelativeMotion>& out) = 0;
  /// What the lidar has shown lately, told before each relative_motions.
  struct LidarState {
    /// unable to pin a direction recently (a scan with a degenerate direction within
    /// `aided_suspect_window_s`)
    bool weak = false;
    /// every direction pinned for `aided_settled_after_s` (so the lidar has fixed the speed and
    /// biases by itself)
    bool settled = false;
  };
  virtual void set_lidar_state(const LidarState& state) { (void)state; }
  /// Whether it expects to add motions for the next state (e.g. a camera whose images are good
  /// enough): the lidar then leaves its weakly constrained directions to it.
  virtual bool active() const = 0;
  /// Adds factors of its own to the window after the new state joined it (the newest state),
  /// before the solve (e.g. a camera's landmark reprojections). Returns the Modality bits of
  /// what it added.
  virtual std::uint8_t add_factors(SlidingWindow& window) {
    (void)window;
    return 0;
  }
  /// Called after every solve with the window as optimised (e.g. for residual statistics).
  virtual void after_solve(const SlidingWindow& window) { (void)window; }
};

}  // namespace posed::estimator
