#include "core/vision/fov_compensation.hpp"

#include <cmath>

namespace posed::vision {

FovCrop fov_crop(const PinholeCamera& thermal, double horizontal_fov_rad, double vertical_fov_rad) {
  FovCrop crop;
  crop.width_px = 2.0 * thermal.fx * std::tan(horizontal_fov_rad / 2.0);  // X', eq. (6)
  crop.height_px = 2.0 * thermal.fy * std::tan(vertical_fov_rad / 2.0);   // Y', eq. (6)
  crop.left_px = thermal.cx - crop.width_px / 2.0;
  crop.top_px = thermal.cy - crop.height_px / 2.0;
  return crop;
}

FovCrop fov_crop(const PinholeCamera& thermal, const PinholeCamera& visible) {
  return fov_crop(thermal, visible.horizontal_fov_rad(), visible.vertical_fov_rad());
}

}  // namespace posed::vision
