#pragma once
// A university campus by day (the `campus` scenario): a ring road laid as a figure of eight, so
// that a drive revisits every place lap after lap and crosses its own path once a lap at a wide
// angle, lined with buildings of varied size, trees, lamp posts, benches and parked cars; and one
// open stretch beside a sports field where the lidar has nothing but the ground (and paint) to
// match within 90 m, a floodlight mast or two beyond, so lidar odometry drifts there (metres on
// one pass) and loop closure has something to correct.
//
// Frame `map`: the crossing at the origin, the lobes along x (the larger one, with the open
// stretch at its far end, towards +x); the ground z = 0 (the scenario's ground slab).

#include <vector>

#include "tools/sim/scenario_random.hpp"
#include "tools/sim/trajectory.hpp"
#include "tools/sim/world.hpp"

namespace posed::sim {

/// What a drive on the campus needs to know of it.
struct CampusShape {
  /// the ring road's centre line, a closed loop of 750-860 m crossing itself at the origin
  PeriodicSpline2 road;
  /// from the centre line to the kerbs [m]
  double road_half_width_m = 0;
  /// the open stretch: the centre line's u in [open_from_u_m, open_from_u_m + open_length_m]
  /// (wrapped), 85-110 m, with nothing but the ground and paint within 90 m of it [m]
  double open_from_u_m = 0, open_length_m = 0;
};

/// Adds the campus's materials and boxes to `world`, drawing the road's shape and the places of
/// everything along it from `rng`. The ground slab is the caller's.
CampusShape build_campus(World& world, ScenarioRng& rng);

}  // namespace posed::sim
