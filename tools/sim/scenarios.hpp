#pragma once
// The named worlds and drives (docs/simulator.md says what each one stresses). A scenario is a
// pure function of (name, seed, duration): the same inputs give the same world and trajectory,
// another seed gives another world and drive of the same kind. Where the world has a road to
// drive elsewhere on (campus, street_night), a drive seed draws another drive through the same
// world (localisation on a prior map): another start, direction, line and speed.
//
//   room          small, well lit, furnished room; slow loop (sanity check)
//   corridor      long, plain corridor with dim lights: lidar scan matching is degenerate along
//                 its axis, the camera sees little texture
//   mine          rough, dark tunnel loop, rocky walls, a few warm machines, headlight only
//   street_night  large loop between buildings at night: street lights, parked cars (some warm),
//                 pedestrians, a cold sky
//   tunnel        a coal mine's straight shotcrete roadway, hundreds of metres, dark (headlight,
//                 a rare lamp): lidar degenerate along it, texture for the colour camera, warm
//                 pipes, cables and fittings along it for the thermal camera; uneven floor
//   smoke         the same kind of roadway, lit by lamps; part-way through, smoke fills the air
//                 for the colour camera and clears again (World::smoke; posectl sim records when)
//   campus        a university campus by day: a figure-of-eight ring road past buildings, trees
//                 and parked cars, revisited lap after lap and crossed once a lap, with an open
//                 stretch by a sports field where the lidar sees little but the ground

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "tools/sim/trajectory.hpp"
#include "tools/sim/world.hpp"

namespace posed::sim {

struct Scenario {
  std::string name;
  World world;
  Trajectory trajectory;
};

/// The known scenario names, in documentation order.
std::span<const std::string_view> scenario_names();

/// Builds scenario `name` for `seed`, with a speed profile covering `duration_s` (plus margin).
/// nullopt + `error` for an unknown name.
std::optional<Scenario> make_scenario(std::string_view name, std::uint64_t seed, double duration_s,
                                      double gravity_mps2, std::string& error);

/// The same, with the drive drawn from `drive_seed` when one is given: the world stays `seed`'s
/// (the same boxes, materials and lights), the drive (start, direction, line within the road,
/// speeds, bumps) comes from a stream of its own. Without one: the scenario as above, byte for
/// byte. campus draws its drive from its own stream always, seeded by `seed` unless
/// `drive_seed` is given (so a drive seed equal to the seed changes nothing); street_night
/// without one keeps the drive it always had (the centre line, from the world's stream). The
/// other scenarios have one drive: nullopt + `error` for a drive seed.
std::optional<Scenario> make_scenario(std::string_view name, std::uint64_t seed,
                                      std::optional<std::uint64_t> drive_seed, double duration_s,
                                      double gravity_mps2, std::string& error);

}  // namespace posed::sim
