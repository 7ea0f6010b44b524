#pragma once
// The fixed-lag window of the lidar-inertial back end (seed 001's Ceres sliding window; VINS-Mono,
// LIO-SAM): the last `size` states at scan times, tied by preintegrated IMU factors (with the bias
// random walk) and anchored by scan-to-map lidar pose factors. When the window is full the oldest
// state is marginalised: the factors that touch it are linearised and its information is kept as
// a Gaussian prior on its neighbour (the Schur complement), so what the dropped states taught
// about velocity and biases is not lost. That is how the IMU biases converge over many windows.
//
// Deterministic: single-threaded Ceres with fixed options and problem order.

#include <Eigen/Geometry>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "core/imu/preintegration.hpp"

namespace ceres {
class CostFunction;
}

namespace posed::estimator {

struct SlidingWindowConfig {
  int size = 10;           ///< states kept [1]
  int max_iterations = 8;  ///< Levenberg-Marquardt iterations per solve [1]
  double gravity_mps2 = 9.805;
  imu::ImuNoise noise;
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();
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
  std::uint64_t iterations = 0;  ///< summed over solves
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
  /// Optimises the window; false when Ceres reported a failure (the states keep their values).
  bool solve();

  bool empty() const { return states_.empty(); }
  std::size_t size() const { return states_.size(); }
  imu::ImuState state(std::size_t i) const;
  imu::ImuState latest() const { return state(states_.size() - 1); }
  /// Marginal covariance of the newest state's pose, tangent [dp (map), dtheta (body)]
  /// [m², rad²], from the window's Gauss-Newton Hessian at the current estimate.
  Eigen::Matrix<double, 6, 6> latest_pose_covariance() const;
  const SlidingWindowCounters& counters() const { return counters_; }

 private:
  struct State {
    HostTime stamp;
    double pose[7];
    double speed_bias[9];
    /// the lidar pose factor on this state, if any
    std::unique_ptr<ceres::CostFunction> lidar;
    /// the IMU factor from the previous state to this one (null for the oldest)
    std::unique_ptr<ceres::CostFunction> imu;
  };
  void marginalise_oldest();

  SlidingWindowConfig config_;
  std::deque<State> states_;
  /// prior on states_.front() (pose, speed_bias)
  std::unique_ptr<ceres::CostFunction> prior_;
  SlidingWindowCounters counters_;
};

}  // namespace posed::estimator
