#pragma once
// The random stream the scenarios build their worlds and drives from (scenarios.cpp,
// roadway.cpp). The order and number of draws is part of what a seed means: changing them
// changes every recording made with that seed (tests/unit/sim/scenarios_test.cpp).

#include <random>

namespace posed::sim {

using ScenarioRng = std::mt19937_64;

/// A uniform draw in [a, b).
inline double uniform(ScenarioRng& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}

}  // namespace posed::sim
