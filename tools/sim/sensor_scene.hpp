#pragma once
// What every simulated sensor observes: the world, the BVH that casts rays into it, and the
// vehicle's drive. run_simulation owns all three and they outlive the sensors.

#include "tools/sim/bvh.hpp"
#include "tools/sim/trajectory.hpp"
#include "tools/sim/world.hpp"

namespace posed::sim {

class MovingObjects;

struct SensorScene {
  const World& world;
  const Bvh& bvh;
  const Trajectory& trajectory;
  /// people and vehicles (--dynamic): each sensor places them at its sample time, casts against
  /// them besides the BVH; null without
  MovingObjects* moving = nullptr;
};

}  // namespace posed::sim
