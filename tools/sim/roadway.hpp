#pragma once
// A straight underground roadway along map x, as a coal mine drives them (the `tunnel` and
// `smoke` scenarios): a shotcrete shell (walls, haunches, crown) and its services, built so that
// the lidar sees the same cross-section all along it while the cameras see what changes.
//
// What each sensor can use to tell one place along the axis from another:
//   lidar    nothing within a few centimetres of the shell and its services, which run the whole
//            length unchanged: couplings and flanges stand 0.5-2 cm proud of their pipe,
//            hangers 1.5 cm of their tray, rock-bolt plates 1.5 cm of the shotcrete. Only the
//            junction boxes (12 cm deep, every 30-60 m) and the machine niches (1.5 m deep,
//            every 150-250 m) stand out, too sparse to pin the axis for long.
//   visible  the shotcrete's blotchy value-noise texture, the bolt plates, couplings, flanges,
//            hangers and junction boxes, as far as the headlight and the lamps light them
//   thermal  bare flanges on the insulated hot-water pipe (bright), galvanised couplings on the
//            warm compressed-air pipe (dark against it: low emissivity), cool hangers across the
//            warm power cables, bolt plates warmer than the shotcrete (steel reaching into warmer
//            rock), warm junction boxes, and a hot transformer or pump in each niche
//
// Frame `map`: the axis is x (y = 0), the floor z = 0 (the scenario's ground slab).

#include "tools/sim/scenario_random.hpp"
#include "tools/sim/world.hpp"

namespace posed::sim {

struct RoadwayLayout {
  /// the shell runs over x in [-half_length, half_length]; closed by end walls there [m]
  double half_length_m = 300.0;
  /// the small things on the shell and its services (bolt plates, couplings, flanges, hangers)
  /// over x in [-detail, detail]: beyond, no sensor resolves them from where the drive goes
  /// (the cameras' 4-pixel ray grid is 40 cm wide at 60 m; the lidar sees them flush) [m]
  double detail_half_length_m = 300.0;
  /// spacing of the roof lamps: drawn in [min, max] [m]
  double lamp_spacing_min_m = 60.0, lamp_spacing_max_m = 120.0;
  /// a lamp's PointLight::intensity [relative at 1 m]
  double lamp_intensity = 0.3;
};

/// What a drive through the roadway needs to know of it.
struct RoadwayShape {
  /// from the axis to the wall faces [m]
  double half_width_m = 0;
  /// from the axis to the nearest service on a wall (pipes, cable trays, junction boxes) [m]
  double clear_half_width_m = 0;
};

/// Adds the roadway's materials, boxes and lamps to `world`, drawing its dimensions and the
/// places of everything along it from `rng`. Uses world.air_temperature_c for the temperatures of
/// unheated things.
RoadwayShape build_roadway(World& world, ScenarioRng& rng, const RoadwayLayout& layout);

}  // namespace posed::sim
