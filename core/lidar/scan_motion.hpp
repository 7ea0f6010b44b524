#pragma once
// Deskew (seed 000 §2.3, LOAM): a spinning lidar fires its points over a whole rotation while the
// robot moves, so a scan's raw points are each in the sensor frame of their own firing time. The
// IMU-propagated motion over the scan (ScanMotion) moves every point into the sensor frame at the
// scan's END, where the estimator places the scan.

#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

#include "core/measurements.hpp"
#include "core/time.hpp"

namespace posed::lidar {

/// IMU-propagated motion of the lidar over one scan, for deskew: the pose of the lidar at each
/// stamp, expressed in the lidar frame at the scan's end (T_end_t), sorted by stamp, spanning at
/// least [scan start, scan end]. Between samples: linear in translation, SLERP in rotation;
/// outside, the nearest sample. Empty: no motion (points are taken as they are).
struct ScanMotion {
  std::vector<HostTime> stamps;
  std::vector<Eigen::Isometry3d> T_end_t;

  void clear() {
    stamps.clear();
    T_end_t.clear();
  }
  /// T_end_t at `t`.
  Eigen::Isometry3d at(HostTime t) const;
};

/// A point of a deskewed scan in the lidar frame at the scan's end.
struct ScanPoint {
  Eigen::Vector3f p;         ///< position [m]
  float range_m = 0;         ///< distance from the sensor at its firing [m]
  float intensity = 0;       ///< calibrated reflectivity [0..255]
  std::uint16_t ring = 0;    ///< beam index by elevation, 0 = lowest
  std::uint16_t column = 0;  ///< azimuth bin of the firing (range image column)
  /// time of the firing relative to the scan's start stamp [ns] (LidarPoint::offset_ns)
  std::int32_t offset_ns = 0;
};

/// Moves every point of `points` (offsets from `scan_start`) into the lidar frame at the scan's
/// end; points outside [min_range_m, max_range_m] and non-finite ones are dropped. `columns` is
/// the range image width (azimuth bins per turn). `out` is cleared first; reserve it once.
void deskew(std::span<const LidarPoint> points, HostTime scan_start, const ScanMotion& motion,
            int columns, float min_range_m, float max_range_m, std::vector<ScanPoint>& out);

}  // namespace posed::lidar
