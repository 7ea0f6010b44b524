#pragma once
// Simulated lidar + IMU runs of the M2DGR rig (config/posed.yaml), cached per process: the
// lidar and estimator tests share them.

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>

#include "core/lidar/scan_motion.hpp"
#include "daemon/config/config_loader.hpp"
#include "tools/sim/lidar_imu_run.hpp"
#include "tools/sim/rig_config.hpp"

namespace posed::test {

inline std::string source_dir() {
  const char* env = std::getenv("POSED_SOURCE_DIR");
  return env != nullptr ? env : POSED_SOURCE_DIR_DEFAULT;
}

/// The rig of config/posed.yaml.
inline sim::SimRig m2dgr_rig() {
  const config::LoadResult loaded = config::load_config_file(source_dir() + "/config/posed.yaml");
  EXPECT_TRUE(loaded.ok()) << loaded.error_text();
  return sim::rig_from_config(loaded.config);
}

/// `duration_s` of `scenario` (seed `seed`), decoded; simulated once per process.
inline const sim::LidarImuRun& simulated(const std::string& scenario, double duration_s,
                                         std::uint64_t seed = 1, bool noise = true) {
  static std::map<std::string, std::unique_ptr<sim::LidarImuRun>> cache;
  const std::string key = scenario + "/" + std::to_string(duration_s) + "/" + std::to_string(seed) +
                          (noise ? "" : "/ideal");
  auto& slot = cache[key];
  if (!slot) {
    slot = std::make_unique<sim::LidarImuRun>();
    sim::SimOptions o;
    o.scenario = scenario;
    o.duration_s = duration_s;
    o.seed = seed;
    o.noise = noise;
    std::string error;
    EXPECT_TRUE(sim::simulate_lidar_imu(m2dgr_rig(), o, *slot, error)) << error;
  }
  return *slot;
}

/// The true motion of the lidar over a scan, for deskew (what the IMU should predict).
inline lidar::ScanMotion true_motion(const sim::LidarImuRun& run, const sim::DecodedScan& scan) {
  lidar::ScanMotion m;
  const Eigen::Isometry3d T_end_inv = run.T_map_lidar(scan.end).inverse();
  for (HostTime t = scan.start - Duration::from_ms(5); t <= scan.end + Duration::from_ms(5);
       t += Duration::from_ms(5)) {
    m.stamps.push_back(t);
    m.T_end_t.push_back(T_end_inv * run.T_map_lidar(t));
  }
  return m;
}

}  // namespace posed::test
