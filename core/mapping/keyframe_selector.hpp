#pragma once
// Which odometry poses become keyframes: the first, then each one that moved or turned enough
// since the last keyframe. Header-only and cheap, so the fusion thread can decide which scans to
// copy for the mapping stage with the same rule the LoopCloser applies.

#include <Eigen/Geometry>
#include <optional>

namespace posed::mapping {

class KeyframeSelector {
 public:
  KeyframeSelector(double distance_m, double angle_rad)
      : distance_m_(distance_m), angle_rad_(angle_rad) {}

  /// Whether `T_odom_base` is far enough from the last keyframe; if so it becomes the last.
  bool take(const Eigen::Isometry3d& T_odom_base) {
    if (last_) {
      const Eigen::Isometry3d T_last_now = last_->inverse() * T_odom_base;
      if (T_last_now.translation().norm() < distance_m_ &&
          Eigen::AngleAxisd(T_last_now.rotation()).angle() < angle_rad_) {
        return false;
      }
    }
    last_ = T_odom_base;
    return true;
  }

 private:
  double distance_m_;
  double angle_rad_;
  std::optional<Eigen::Isometry3d> last_;
};

}  // namespace posed::mapping
