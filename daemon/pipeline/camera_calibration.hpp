#pragma once
// The D435i's factory calibration in the configuration (issue 6): with
// `visible_camera.intrinsics_source: factory`, a live colour camera's intrinsics come from the
// camera itself over its HW monitor (drivers/camera/d4xx_calibration_reader.hpp); when the camera
// cannot be asked (no device, no permission, a bad answer) the configured ones stay and one
// warning says why. The factory distortion is Intel's inverse Brown-Conrady (it maps distorted
// to undistorted coordinates); posed's camera model is the forward radial-tangential one, so the
// forward coefficients are fitted to it over the image.

#include <array>
#include <string>

#include "daemon/config/posed_config.hpp"
#include "drivers/camera/usb_transport.hpp"

namespace posed::pipeline {

struct ForwardDistortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;
  double rms_px = 0;  ///< fit residual over the image [px]
  double max_px = 0;  ///< largest residual [px]
};

/// Forward radial-tangential coefficients that reproduce librealsense's inverse Brown-Conrady
/// `coeffs` (k1, k2, p1, p2, k3 as rs2_intrinsics holds them) over a width x height image with
/// focal lengths fx, fy and principal point cx, cy [px], by linear least squares on a grid.
ForwardDistortion forward_from_inverse_brown_conrady(const std::array<double, 5>& coeffs, double fx,
                                                     double fy, double cx, double cy, int width,
                                                     int height);

/// Applies the factory calibration read over `usb` to `config.visible_camera` when asked to
/// (intrinsics_source: factory). Returns one line for the log saying which intrinsics are used,
/// or nothing when the camera could not be asked (the reader has logged the one warning).
std::string apply_d435i_factory_calibration(config::PosedConfig& config,
                                            drivers::camera::UsbTransport& usb);

}  // namespace posed::pipeline
