#pragma once
// A pinhole camera with radial-tangential (plumb bob, k1 k2 p1 p2) distortion: the model of
// M2DGR's calibration for both the D435i colour and the PLUG 617 thermal camera (and of
// `visible_camera.*` / `thermal_camera.*` in the daemon's config). Camera frame: x right, y down,
// z forward; pixel (0, 0) is the centre of the top-left pixel (OpenCV's convention).

#include <Eigen/Core>

namespace posed::vision {

struct PinholeCamera {
  int width = 0;   ///< image width [px]
  int height = 0;  ///< image height [px]
  double fx = 0;   ///< focal length along x [px]
  double fy = 0;   ///< focal length along y [px]
  double cx = 0;   ///< principal point x [px]
  double cy = 0;   ///< principal point y [px]
  double k1 = 0;   ///< radial distortion r^2 coefficient [-]
  double k2 = 0;   ///< radial distortion r^4 coefficient [-]
  double p1 = 0;   ///< tangential distortion [-]
  double p2 = 0;   ///< tangential distortion [-]

  /// The intrinsic matrix K (pixels from normalised, undistorted coordinates).
  Eigen::Matrix3d K() const;

  /// Normalised undistorted (x/z, y/z) -> normalised distorted coordinates.
  Eigen::Vector2d distort(const Eigen::Vector2d& xy) const;

  /// Normalised undistorted coordinates -> pixel [px].
  Eigen::Vector2d pixel_from_normalised(const Eigen::Vector2d& xy) const;

  /// A point in the camera frame [m] -> pixel [px]; false when it is not in front (z <= 0).
  bool project(const Eigen::Vector3d& p_cam, Eigen::Vector2d& pixel) const;

  /// Pixel [px] -> normalised undistorted coordinates, by Gauss-Newton on the distortion model
  /// (OpenCV's fixed-point undistortPoints stalls under the thermal lens's k1 = -0.44). False
  /// when it does not converge to 1e-9 px.
  bool normalised_from_pixel(const Eigen::Vector2d& pixel, Eigen::Vector2d& xy) const;

  /// Field of view of the undistorted pinhole of this size and focal length, eq. (2)-(4) of
  /// seed 000: 2 atan(W / (2 fx)) horizontally, 2 atan(H / (2 fy)) vertically [rad].
  double horizontal_fov_rad() const;
  double vertical_fov_rad() const;

  /// True when every parameter is usable (positive size and focal lengths).
  bool valid() const { return width > 0 && height > 0 && fx > 0 && fy > 0; }
};

}  // namespace posed::vision
