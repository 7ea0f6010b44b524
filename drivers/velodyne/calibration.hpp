#pragma once
// The per-laser correction table. The fields and their meaning are those of the VeloView /
// ros-drivers calibration files (ros-drivers velodyne_pointcloud calibration.h); angles in
// radians, lengths in metres. `rot_correction_rad` is subtracted from the block azimuth (a
// VLP-32C laser whose manual azimuth offset is +1.4° has rot_correction −1.4°).

#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "drivers/velodyne/packet_format.hpp"

namespace posed::drivers::velodyne {

/// Calibration tables and files give angles in degrees.
inline constexpr double kDegToRad = std::numbers::pi / 180.0;

struct LaserCorrection {
  /// azimuth correction, subtracted from the firing's azimuth [rad]
  double rot_correction_rad = 0.0;
  /// elevation of the beam above the sensor's x-y plane [rad]
  double vert_correction_rad = 0.0;
  /// added to every measured distance [m]
  double dist_correction_m = 0.0;
  /// vertical offset of the beam origin from the sensor origin [m]
  double vert_offset_m = 0.0;
  /// horizontal offset of the beam origin, perpendicular to the beam [m]
  double horiz_offset_m = 0.0;
};

struct Calibration {
  /// indexed by laser id (0 .. laser_count-1)
  std::vector<LaserCorrection> lasers;
  /// distance LSB [m]; 0 = the model's (4 mm VLP-32C, 2 mm VLP-16/HDL-32E)
  double distance_resolution_m = 0.0;
  /// where the table came from ("builtin VLP-32C" or a path), for messages
  std::string source;
};

/// The nominal table from the user manual (VLP-32C table 9-2 "Laser ID, Vertical Angle and
/// Azimuth Offset"; VLP-16 table 9-1; HDL-32E appendix "Vertical Angles"). Empty for kUnknown.
Calibration builtin_calibration(ProductId product);

/// Ring of each laser: 0 = lowest elevation; ties broken by laser id so rings are unique.
std::vector<std::uint16_t> rings_by_elevation(const Calibration& calibration);

}  // namespace posed::drivers::velodyne
