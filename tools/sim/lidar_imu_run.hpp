#pragma once
// A simulated run decoded as the daemon would decode it, in memory: the VLP-32C packets through
// the real ScanBuilder (decoder, ClockSync, scan assembler) into host-stamped scans, the A9 frames
// through the real decoder and ClockSync into IMU samples, and the ground truth. For the lidar and
// estimator tests and `posectl bench lio`, which need scans and IMU without a file or a daemon.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/measurements.hpp"
#include "tools/sim/sim_sink.hpp"
#include "tools/sim/simulator.hpp"

namespace posed::sim {

struct DecodedScan {
  std::vector<LidarPoint> points;  ///< offsets from `start`
  HostTime start, end;             ///< host clock (ClockSync of the packets' device time)
};

struct LidarImuRun {
  SimRig rig;
  std::vector<DecodedScan> scans;
  std::vector<ImuSample> imu;  ///< IMU frame, host-stamped by ClockSync
  std::vector<MemorySink::Pose> truth;

  /// base_link in map at host time `t`, interpolated from the ground truth (clamped at the ends).
  Eigen::Isometry3d T_map_base(HostTime t) const;
  /// the lidar in map at `t`
  Eigen::Isometry3d T_map_lidar(HostTime t) const { return T_map_base(t) * rig.T_imu_lidar; }
};

/// Simulates `options` (cameras off) on `rig` and decodes it. false + `error` on a bad scenario.
bool simulate_lidar_imu(const SimRig& rig, SimOptions options, LidarImuRun& out,
                        std::string& error);

}  // namespace posed::sim
