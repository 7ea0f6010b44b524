// The named scenarios: the four older ones still build the worlds and drives (and the sensors
// still send the bytes) their seeds have always given, so recordings made before stay
// reproducible.

#include "tools/sim/scenarios.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "daemon/config/config_loader.hpp"
#include "tools/sim/rig_config.hpp"
#include "tools/sim/simulator.hpp"

namespace posed::sim {
// Named rather than anonymous: test files build as unity batches.
namespace scenarios_test {

/// FNV-1a 64 over integers.
class Fnv {
 public:
  void mix(std::int64_t v) {
    for (int i = 0; i < 8; ++i) {
      hash_ ^= static_cast<std::uint64_t>(v >> (8 * i)) & 0xFFu;
      hash_ *= 0x100000001b3ull;
    }
  }
  /// A value in µ-units (µm, µrad, ...): the draws and the geometry, not libm's last bits.
  void mix(double v) { mix(static_cast<std::int64_t>(std::llround(v * 1e6))); }
  void mix(const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) mix(v[i]);
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ull;
};

/// Everything a scenario builds: environment, materials, boxes, lights, and the drive sampled
/// every 2.5 s over `duration_s`.
std::uint64_t scenario_hash(const Scenario& s, double duration_s) {
  Fnv h;
  const World& w = s.world;
  for (double v :
       {w.ambient, w.sky_temperature_c, w.sky_radiance, w.headlight, w.air_temperature_c})
    h.mix(v);
  for (const Material& m : w.materials) {
    for (double v : {m.reflectivity, m.albedo, m.texture_contrast, m.temperature_c, m.emission})
      h.mix(v);
    h.mix(static_cast<std::int64_t>(m.texture));
    h.mix(m.tint_bgr);
  }
  for (const Box& b : w.boxes) {
    h.mix(b.center_m);
    h.mix(b.half_extent_m);
    for (int c = 0; c < 3; ++c) h.mix(Eigen::Vector3d(b.R_map_box.col(c)));
    h.mix(static_cast<std::int64_t>(b.material));
  }
  for (const PointLight& l : w.lights) {
    h.mix(l.p_map_m);
    h.mix(l.intensity);
  }
  h.mix(s.trajectory.path().length());
  for (double t = 0; t <= duration_s; t += 2.5) {
    const TrajectorySample p = s.trajectory.at(t);
    h.mix(p.p_map_base_m);
    h.mix(Eigen::Vector3d(p.q_map_base.vec()));
    h.mix(p.v_map_mps);
  }
  return h.value();
}

TEST(Scenarios, OlderScenariosBuildWhatTheyAlwaysBuilt) {
  // Computed on the code before tunnel and smoke were added (commit 606cc25): a change in the
  // order or number of a scenario's random draws, or in what it builds, changes its hash.
  struct Expected {
    const char* name;
    std::uint64_t hash;
  };
  const Expected expected[] = {
      {"street_night", 0x9ff47617a4ee4dafull},
      {"corridor", 0xf9bb5293e5d39e86ull},
      {"mine", 0x67321d96bdce67cbull},
      {"room", 0xb47889c13683a564ull},
  };
  for (const Expected& e : expected) {
    std::string error;
    const auto s = make_scenario(e.name, 5, 120.0, 9.805, error);
    ASSERT_TRUE(s) << error;
    const std::uint64_t hash = scenario_hash(*s, 120.0);
    EXPECT_EQ(hash, e.hash) << e.name << ": 0x" << std::hex << hash;
  }
}

TEST(Scenarios, OlderScenariosSendTheBytesTheyAlwaysSent) {
  // Every sensor, noise on, over the first 0.3 s (the first colour and thermal frames, 450 lidar
  // packets): what `posectl sim` records for the seed, through the shared rendering code.
  // Computed on the code before tunnel and smoke were added (commit 606cc25) with this
  // toolchain (GCC, glibc's libm): a new compiler or libm may legitimately change the last bits
  // of the rendering; compare `posectl sim` recordings of the old and new build with cmp then.
  struct Expected {
    const char* name;
    std::uint64_t hash;
  };
  const Expected expected[] = {
      {"street_night", 0x6c8cc3ac245fa68aull},
      {"corridor", 0xb9a26cf1ec97b0a8ull},
      {"mine", 0x86368c3894a7c4faull},
      {"room", 0x489733af0f18effaull},
  };
  const SimRig rig = rig_from_config(config::default_config());
  for (const Expected& e : expected) {
    SimOptions o;
    o.scenario = e.name;
    o.duration_s = 0.3;
    o.seed = 5;
    HashSink sink;
    SimSummary summary;
    std::string error;
    ASSERT_TRUE(run_simulation(rig, o, sink, summary, error)) << error;
    EXPECT_EQ(sink.hash(), e.hash) << e.name << ": 0x" << std::hex << sink.hash();
  }
}

}  // namespace scenarios_test
}  // namespace posed::sim
