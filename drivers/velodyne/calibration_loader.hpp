#pragma once
// Reads the three calibration formats users have for the same per-laser table:
//   - VeloView XML (boost serialization archive: <DB><distLSB_> [cm], <enabled_>, <points_><item>
//     <px><id_>, <rotCorrection_>/<vertCorrection_> [deg], <distCorrection_>, offsets [cm])
//   - ros-drivers velodyne_pointcloud YAML (lasers: [{laser_id, rot_correction, vert_correction
//     [rad], dist_correction, vert_offset_correction, horiz_offset_correction [m]}],
//     num_lasers, distance_resolution [m])
//   - velodyne_decoder / nebula YAML (the same keys; flow style with trailing commas)
// The format is chosen by content (an XML declaration or root element), not by file name.

#include <string>
#include <string_view>

#include "drivers/velodyne/calibration.hpp"

namespace posed::drivers::velodyne {

/// Loads `path` into `out`. On failure returns false and sets `error` to
/// "calibration file PATH line N: reason".
bool load_calibration(const std::string& path, Calibration& out, std::string& error);

/// The same from text already in memory; `name` is used in messages.
bool parse_calibration_xml(std::string_view text, std::string_view name, Calibration& out,
                           std::string& error);
bool parse_calibration_yaml(std::string_view text, std::string_view name, Calibration& out,
                            std::string& error);
/// Either format, chosen by content as load_calibration does.
bool parse_calibration_text(std::string_view text, std::string_view name, Calibration& out,
                            std::string& error);

}  // namespace posed::drivers::velodyne
