#pragma once
// A simulated scan as the mapping stage receives it: deskewed with the true motion and put in
// base_link.

#include <vector>

#include "core/lidar/scan_motion.hpp"
#include "tests/unit/lidar/sim_fixture.hpp"

namespace posed::test {

inline void deskewed_base(const sim::LidarImuRun& run, const sim::DecodedScan& scan,
                          std::vector<Eigen::Vector3f>& points_base) {
  std::vector<lidar::ScanPoint> deskewed;
  lidar::deskew(scan.points, scan.start, true_motion(run, scan), 1800, 0.5f, 100.f, deskewed);
  const Eigen::Isometry3f T_base_lidar = run.rig.T_imu_lidar.cast<float>();
  points_base.clear();
  for (const lidar::ScanPoint& p : deskewed) {
    points_base.push_back(T_base_lidar * p.p);
  }
}

}  // namespace posed::test
