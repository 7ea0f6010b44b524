#pragma once
// Gravity alignment for a rig that does not stand still at start-up (a robot already driving
// when posed starts or restarts): over a window, every specific-force sample is rotated by the
// integrated gyro into the frame at the window's start and averaged. That average is
// R_0ᵀ (mean acceleration - g): over a few seconds of ordinary driving the mean acceleration is
// a small fraction of g, so it gives roll and pitch to within a degree or two. The estimator
// starts from it with that uncertainty and an unknown velocity; the lidar-inertial window then
// observes both.

#include <Eigen/Geometry>
#include <optional>

#include "core/imu/static_alignment.hpp"
#include "core/measurements.hpp"

namespace posed::imu {

struct MovingAlignmentConfig {
  double gravity_mps2 = 9.805;            ///< [m/s^2]
  Duration window = Duration::from_s(2);  ///< samples averaged
};

class MovingAlignment {
 public:
  explicit MovingAlignment(const MovingAlignmentConfig& config) : config_(config) {}
  /// Feeds one sample; the result once a window is complete: the attitude at that last sample
  /// (yaw 0), a zero gyro bias (not observable while moving), and a tilt uncertainty from the
  /// mean acceleration the window could have held.
  std::optional<StaticAlignmentResult> add(const ImuSample& sample);
  void reset();

 private:
  MovingAlignmentConfig config_;
  std::optional<ImuSample> previous_;
  HostTime start_;
  Eigen::Quaterniond q_start_now_ = Eigen::Quaterniond::Identity();  ///< frame now in start
  Eigen::Vector3d sum_f_start_ = Eigen::Vector3d::Zero();
  std::uint64_t samples_ = 0;
};

}  // namespace posed::imu
