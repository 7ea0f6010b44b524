#pragma once
// The fixed-lag window of the back end (seed 001's Ceres sliding window; VINS-Mono, LIO-SAM): the
// last `size` states at scan times, and one list of factors over their parameter blocks
// (window_factor.hpp): preintegrated IMU between consecutive states (with the bias random walk),
// scan-to-map lidar poses, camera relative motions, and a prior. Solve, marginalisation and
// covariance each iterate over that list and know no factor kind.
//
// When the window is full the oldest state is marginalised: every factor that touches its blocks
// is linearised at the current estimate, the state's tangent coordinates are eliminated from those
// normal equations (Schur complement), and what remains becomes one Gaussian prior on every block
// those factors also touched (MarginalPrior). So what the dropped states taught about velocity and
// biases is not lost; that is how the IMU biases converge over many windows.
//
// Deterministic: single-threaded Ceres with fixed options, and factors in insertion order.

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "core/estimator/window_factor.hpp"
#include "core/imu/preintegration.hpp"

namespace posed::estimator {

struct SlidingWindowConfig {
  int size = 10;           ///< states kept [1]
  int max_iterations = 8;  ///< Levenberg-Marquardt iterations per solve [1]
  double gravity_mps2 = 9.805;
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();
  /// Estimate the map frame's tilt (gravity's direction in map) as a block of the window, shared
  /// by every IMU factor and kept through marginalisation (docs/estimator.md, Known limits)
  bool estimate_gravity_tilt = false;
  /// its prior at a reset, 1 sigma per axis [rad]
  double gravity_tilt_prior_rad = 0.02;
  /// The tilt is held (a constant in the solve) until the heading has spanned this much since
  /// the window began: driving one way, a tilt and a body-fixed accelerometer bias look the same,
  /// and freeing the tilt there only weakens the IMU along the way driven [rad]. 0: never held.
  double gravity_tilt_release_yaw_rad = 0.0;
};

/// A lidar pose measurement for one state.
struct LidarPose {
  Eigen::Isometry3d T_map_lidar = Eigen::Isometry3d::Identity();
  /// (rotation, translation), right perturbation; zero along degenerate directions
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
};

struct SlidingWindowCounters {
  std::uint64_t solves = 0;
  std::uint64_t failed_solves = 0;
  std::uint64_t marginalised = 0;
  std::uint64_t iterations = 0;        ///< summed over solves
  std::uint64_t solves_tilt_free = 0;  ///< solves with the map's tilt a block of the window
  /// factors added, by FactorKind [1]
  std::array<std::uint64_t, kFactorKinds> factors_added{};
};

class SlidingWindow {
 public:
  explicit SlidingWindow(const SlidingWindowConfig& config);
  ~SlidingWindow();
  SlidingWindow(const SlidingWindow&) = delete;
  SlidingWindow& operator=(const SlidingWindow&) = delete;

  /// Empties the window and starts it with `state` under a Gaussian prior: tangent order
  /// [dp (map), dtheta (body), v, b_g, b_a], `prior_sigma` its 1-sigma per coordinate.
  void reset(const imu::ImuState& state, const Eigen::Matrix<double, 15, 1>& prior_sigma);
  /// Adds a state `guess` (its initial value: the IMU prediction) tied to the newest by `pre`,
  /// with an optional lidar pose. Marginalises the oldest when the window is over its size.
  void add(const imu::ImuState& guess, const imu::Preintegration& pre,
           const std::optional<LidarPose>& lidar);
  /// Adds a factor on the blocks `refs` (in the cost function's order). False, and nothing
  /// added, when a referenced state has left the window or the sizes do not match.
  bool add_factor(FactorKind kind, std::unique_ptr<ceres::CostFunction> cost,
                  const std::vector<BlockRef>& refs,
                  std::unique_ptr<ceres::LossFunction> loss = nullptr);
  /// Optimises the window; false when Ceres reported a failure (the states keep their values).
  bool solve();

  bool empty() const { return states_.empty(); }
  std::size_t size() const { return states_.size(); }
  imu::ImuState state(std::size_t i) const;
  imu::ImuState latest() const { return state(states_.size() - 1); }
  /// The id of state i: counts states since construction, stable while the state is in the
  /// window, never reused.
  std::uint64_t id(std::size_t i) const { return states_.at(i).id; }
  std::uint64_t latest_id() const { return states_.back().id; }
  /// The index of the state with `id`, if it is still in the window.
  std::optional<std::size_t> index_of(std::uint64_t id) const;
  /// Marginal covariance of the newest state's pose, tangent [dp (map), dtheta (body)]
  /// [m², rad²], from the window's Gauss-Newton Hessian at the current estimate.
  Eigen::Matrix<double, 6, 6> latest_pose_covariance() const;
  /// The factors now in the window, by kind [1].
  std::array<std::size_t, kFactorKinds> factor_counts() const;
  /// Whitened residual norm |r| of every factor of `kind` at the current estimate, in list order.
  void residual_norms(FactorKind kind, std::vector<double>& out) const;
  const SlidingWindowCounters& counters() const { return counters_; }
  /// Gravity in the map frame as the window estimates it [m/s²]: (0, 0, -g) unless it
  /// estimates the map's tilt.
  Eigen::Vector3d gravity_map() const;
  /// The estimated tilt of the map frame about its x and y [rad] (zero unless estimated).
  Eigen::Vector2d gravity_tilt() const { return {gravity_tilt_[0], gravity_tilt_[1]}; }
  /// The caller's say on whether the lidar pins the position of the states it adds from now
  /// (not along a corridor's axis, not on an open stretch). Only headings turned through at
  /// pinned states count towards releasing the tilt: there a turn tells it from the bias. True
  /// until said otherwise.
  void set_position_pinned(bool pinned) { position_pinned_ = pinned; }
  /// Whether the tilt is a block of the window yet: estimated, and the headings of pinned states
  /// have spanned enough. From then on it stays one, through resets. Before, it is zero and no
  /// factor has it: the window is the one without tilt estimation, to the bit.
  bool gravity_tilt_free() const { return tilt_released_; }
  /// The span of headings the window's states have had at pinned positions since it began [rad].
  double heading_span_rad() const {
    return heading_min_rad_ ? *heading_max_rad_ - *heading_min_rad_ : 0.0;
  }

 private:
  struct State {
    std::uint64_t id = 0;
    HostTime stamp;
    double pose[7];
    double speed_bias[9];
  };
  double* block(const BlockRef& ref);
  void marginalise_oldest();
  void track_heading(const Eigen::Quaterniond& q_map_imu);  // of a state being added
  void release_gravity_tilt_when_observable();
  void add_gravity_tilt_prior();

  SlidingWindowConfig config_;
  std::deque<State> states_;  // references stay valid as states come and go at the ends
  std::vector<WindowFactor> factors_;
  std::uint64_t next_id_ = 1;
  SlidingWindowCounters counters_;
  // The map frame's tilt (kGravityTilt); kept through resets: the map it belongs to stays.
  double gravity_tilt_[2] = {0.0, 0.0};
  // Heading (yaw of the IMU's x axis in map), unwrapped across states, and its extremes over
  // pinned states [rad]; kept through resets like the tilt.
  std::optional<double> heading_rad_;
  std::optional<double> heading_min_rad_, heading_max_rad_;
  bool position_pinned_ = true;
  bool tilt_released_ = false;
};

}  // namespace posed::estimator
