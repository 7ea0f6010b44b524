#pragma once
// Hand-built scenes for the camera tests: the vehicle standing still, and boxes placed where a
// camera on it sees them, in that camera's own frame (x right, y down, z forward), so a test
// knows every pixel's true surface without casting a ray.

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "tools/sim/bvh.hpp"
#include "tools/sim/sensor_scene.hpp"
#include "tools/sim/trajectory.hpp"
#include "tools/sim/world.hpp"

namespace posed::sim::test {

/// A vehicle that never moves: a 100 m square loop and a speed profile without ramps.
inline Trajectory standing_vehicle() {
  const PeriodicSpline2 loop({{0, 0}, {100, 0}, {100, 100}, {0, 100}});
  return Trajectory(loop, SpeedProfile(std::vector<SpeedRamp>{}), TrajectoryConfig{});
}

/// A world, its BVH and a standing vehicle, with a camera at T_base_cam on it.
class CameraTestScene {
 public:
  explicit CameraTestScene(const Eigen::Isometry3d& T_base_cam)
      : trajectory_(standing_vehicle()),
        T_map_cam_(trajectory_.T_map_base(Duration::from_ns(0)) * T_base_cam) {}

  World& world() { return world_; }
  const Eigen::Isometry3d& T_map_cam() const { return T_map_cam_; }

  /// A box with its centre at `p_cam_m` and half extents along the camera's axes, turned by
  /// `yaw_rad` about the camera's y axis (a wall seen obliquely).
  void add_box(const Eigen::Vector3d& p_cam_m, const Eigen::Vector3d& half_extent_m,
               std::uint32_t material, double yaw_rad = 0.0) {
    Box b;
    b.center_m = T_map_cam_ * p_cam_m;
    b.half_extent_m = half_extent_m;
    b.R_map_box =
        T_map_cam_.linear() * Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitY()).matrix();
    b.material = material;
    world_.boxes.push_back(b);
  }
  /// Call once every box is in; the scene must outlive the sensors built on it.
  SensorScene finish() {
    bvh_ = Bvh(world_);
    return {world_, bvh_, trajectory_};
  }

 private:
  World world_;
  Bvh bvh_;
  Trajectory trajectory_;
  Eigen::Isometry3d T_map_cam_;
};

/// A camera looking forward along base_link's x axis (optical z = base x, x = −base y).
inline Eigen::Isometry3d forward_camera() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T.translation() = Eigen::Vector3d(0.5, 0, 0.8);
  return T;
}

}  // namespace posed::sim::test
