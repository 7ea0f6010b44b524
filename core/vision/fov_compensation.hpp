#pragma once
// FOV compensation of seed 000 (§2.1.1, eq. 1-6, Fig. 2): the thermal camera sees more than the
// visible one (M2DGR: 72.6 x 60.8 deg against 54.7 x 42.6 deg for the undistorted pinholes), so the
// undistorted thermal image is cropped to the visible camera's field of view and resampled to the
// visible resolution.
//
// With the focal lengths in pixels d_x = d a, d_y = d b (eq. 1), a crop of X' x Y' pixels spans
// beta' = 2 atan(X' / 2 d_x) and alpha' = 2 atan(Y' / 2 d_y) (eq. 5), so the crop that spans the
// visible camera's FOV is (eq. 6)
//   X' = 2 d_x tan(beta'/2),   Y' = 2 d_y tan(alpha'/2).
// The crop is centred on the thermal principal point (the optical axis the FOV is measured
// around; the paper's Fig. 2 centres it on the image).
//
// ThermalAligner's default mode replaces this crop by the full registration (K_v R K_t^-1, which
// also honours the principal points and the extrinsic rotation); the crop stays available as
// AlignMode::kFovCrop, and this function gives its size.

#include "core/vision/pinhole_camera.hpp"

namespace posed::vision {

/// A crop of the undistorted thermal image, in its pixels.
struct FovCrop {
  double width_px = 0;   ///< X' of eq. (6) [px]
  double height_px = 0;  ///< Y' of eq. (6) [px]
  double left_px = 0;    ///< left edge: principal point x - X'/2 [px]
  double top_px = 0;     ///< top edge: principal point y - Y'/2 [px]
};

/// Eq. (6): the crop of `thermal`'s undistorted image spanning `horizontal_fov_rad` (beta') by
/// `vertical_fov_rad` (alpha').
FovCrop fov_crop(const PinholeCamera& thermal, double horizontal_fov_rad, double vertical_fov_rad);

/// Eq. (6) with the visible camera's pinhole FOV (eq. 2-4 from its size and focal lengths).
FovCrop fov_crop(const PinholeCamera& thermal, const PinholeCamera& visible);

}  // namespace posed::vision
