#pragma once
// `posectl sim --dynamic`: people and vehicles moving through the world, seen by every sensor.
// People walk along the robot's loop beside its path, with it or against it (10 per 100 m of
// loop, 0.9 m to either side, 0.7-1.6 m/s); on the street, vehicles drive in the lane beside it
// (4 per 100 m, 3-9 m/s), so each passes the robot or is passed by it. Their boxes are appended
// to the world after the static BVH was built (which never returns them): every sensor places
// them at its own sample time (place()) before it casts, and tests them itself (cast(),
// overlay()). A person is 0.3 x 0.5 x 1.75 m at 30 °C (clothes over skin), a vehicle 4.4 x 1.8 x
// 1.5 m, its body at 35 °C; both reflect, texture and shade as the world's materials do. They
// cast no shadows, and pass through each other and through anything static in their way.

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/time.hpp"
#include "tools/sim/gbuffer.hpp"
#include "tools/sim/trajectory.hpp"
#include "tools/sim/world.hpp"

namespace posed::sim {

class MovingObjects {
 public:
  /// Adds the objects' boxes and materials to `world` (after its BVH was built) for a drive
  /// along `trajectory`'s loop; `vehicles`: the scenario has a road beside the path.
  MovingObjects(World& world, const Trajectory& trajectory, bool vehicles, std::uint64_t seed);

  /// Moves every object's box to where it is at true time `t`.
  void place(Duration t);
  /// The nearest moving box the ray meets before `t_max_m` (world box index), as place() left
  /// them.
  std::optional<RayHit> cast(const Eigen::Vector3d& origin_m, const Eigen::Vector3d& dir,
                             double t_max_m) const;
  /// Draws the objects (as place() left them) over a camera's G-buffer rendered at `T_map_cam`:
  /// pixels whose ray meets a moving box nearer than what they saw take its hit, and their cells
  /// stop being one plane.
  void overlay(const PixelRays& rays, const Eigen::Isometry3d& T_map_cam, double max_range_m,
               GBuffer& out) const;

  std::size_t people() const { return people_; }
  std::size_t vehicles() const { return objects_.size() - people_; }
  /// "N people, M vehicles", for the recording's metadata
  std::string describe() const;

 private:
  struct Object {
    double u0_m = 0;       ///< position along the loop at t = 0 [m]
    double speed_mps = 0;  ///< along the loop; negative: against the robot's direction
    double lateral_m = 0;  ///< to the left of the path (+) or right (-) [m]
  };
  World& world_;
  const Trajectory& trajectory_;
  std::vector<Object> objects_;
  std::size_t people_ = 0;
  /// index of the first moving box in world_.boxes
  std::size_t first_box_ = 0;
};

}  // namespace posed::sim
