// posectl bench sim: how fast the simulator produces data on one core, per sensor set, as the
// real-time factor (simulated seconds per wall-clock second; ≥ 1 means faster than the rig).

#include <chrono>
#include <string>

#include "tools/posectl/bench.hpp"
#include "tools/sim/simulator.hpp"

namespace posed::posectl {

int bench_sim() {
  struct Case {
    const char* metric;
    const char* scenario;
    bool lidar, cameras;
  };
  const Case cases[] = {
      {"street_night_all_rtf", "street_night", true, true},
      {"street_night_lidar_imu_rtf", "street_night", true, false},
      {"street_night_cameras_imu_rtf", "street_night", false, true},
      {"room_all_rtf", "room", true, true},
      {"mine_all_rtf", "mine", true, true},
  };
  sim::SimRig rig;  // M2DGR-like geometry without reading a config file
  rig.T_imu_lidar.translation() = Eigen::Vector3d(0.27255, -0.00053, 0.17954);
  rig.T_imu_cam.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  rig.T_imu_cam.translation() = Eigen::Vector3d(0.57711, 0.00012, 0.83330);
  rig.T_cam_thermal.translation() = Eigen::Vector3d(-0.17, 0, 0);
  rig.thermal = {640, 512, 435.84, 435.91, 324.45, 255.55, -0.436, 0.166, 0, 0};
  rig.visible = {640, 480, 617.97, 616.45, 327.71, 253.98, 0.148, -0.218, 0, 0};
  for (const Case& c : cases) {
    sim::SimOptions o;
    o.scenario = c.scenario;
    o.duration_s = 10.0;
    o.seed = 1;
    o.lidar = c.lidar;
    o.visible_camera = o.thermal_camera = c.cameras;
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
