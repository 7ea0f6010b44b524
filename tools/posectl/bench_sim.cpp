// posectl bench sim: how fast the simulator produces data on one core, per sensor set, as the
// real-time factor (simulated seconds per wall-clock second; ≥ 1 means faster than the rig).
// The target (docs/simulator.md) is 60 s of all four sensors in ≤ 60 s: the street_night cases
// simulate the full 60 s, the others 10 s. Output goes to a hashing sink (no file, no writer
// thread), so the figure is the simulator's own.

#include <chrono>
#include <string>

#include "daemon/config/config_loader.hpp"
#include "tools/posectl/bench.hpp"
#include "tools/sim/rig_config.hpp"
#include "tools/sim/simulator.hpp"

namespace posed::posectl {

int bench_sim() {
  struct Case {
    const char* metric;
    const char* scenario;
    double duration_s;
    bool lidar, cameras, depth;
    sim::ThermalFormat thermal;
  };
  using sim::ThermalFormat;
  const Case cases[] = {
      {"street_night_all_rtf", "street_night", 60, true, true, false, ThermalFormat::kY8},
      {"street_night_all_depth_rtf", "street_night", 60, true, true, true, ThermalFormat::kY8},
      {"street_night_all_depth_y16_rtf", "street_night", 10, true, true, true, ThermalFormat::kY16},
      {"street_night_lidar_imu_rtf", "street_night", 10, true, false, false, ThermalFormat::kY8},
      {"street_night_cameras_imu_rtf", "street_night", 10, false, true, false, ThermalFormat::kY8},
      {"room_all_rtf", "room", 10, true, true, false, ThermalFormat::kY8},
      {"corridor_all_rtf", "corridor", 10, true, true, false, ThermalFormat::kY8},
      {"mine_all_rtf", "mine", 10, true, true, false, ThermalFormat::kY8},
      {"tunnel_all_rtf", "tunnel", 10, true, true, false, ThermalFormat::kY8},
      // Its 10 s hold 2-3 s of dense smoke, from 30-45 % in: the smoke is rendered and timed.
      {"smoke_all_rtf", "smoke", 10, true, true, false, ThermalFormat::kY8},
  };
  // The schema's defaults are the M2DGR rig of config/posed.yaml, without reading a file.
  const sim::SimRig base_rig = sim::rig_from_config(config::default_config());
  for (const Case& c : cases) {
    sim::SimRig rig = base_rig;
    rig.thermal_format = c.thermal;
    sim::SimOptions o;
    o.scenario = c.scenario;
    o.duration_s = c.duration_s;
    o.seed = 1;
    o.lidar = c.lidar;
    o.visible_camera = o.thermal_camera = c.cameras;
    o.depth_camera = c.depth;
    sim::HashSink sink;
    sim::SimSummary summary;
    std::string error;
    const auto t0 = std::chrono::steady_clock::now();
    if (!sim::run_simulation(rig, o, sink, summary, error)) {
      std::fprintf(stderr, "bench sim: %s\n", error.c_str());
      return 1;
    }
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    report("sim", c.metric, o.duration_s / wall, "x");
  }
  return 0;
}

}  // namespace posed::posectl
