#include "daemon/pipeline/camera_calibration.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <vector>

#include "drivers/camera/d4xx_calibration_reader.hpp"

namespace posed::pipeline {

ForwardDistortion forward_from_inverse_brown_conrady(const std::array<double, 5>& c, double fx,
                                                     double fy, double cx, double cy, int width,
                                                     int height) {
  // Samples: distorted pixels on a 24 x 18 grid over the image; their undistorted coordinates
  // by the inverse model (librealsense rs2_deproject_pixel_to_point, inverse Brown-Conrady).
  constexpr int kCols = 24, kRows = 18;
  std::vector<Eigen::Vector2d> undistorted, distorted;
  for (int r = 0; r < kRows; ++r) {
    for (int col = 0; col < kCols; ++col) {
      const double u = (width - 1) * col / double(kCols - 1);
      const double v = (height - 1) * r / double(kRows - 1);
      const double x = (u - cx) / fx, y = (v - cy) / fy;
      const double r2 = x * x + y * y;
      const double f = 1 + c[0] * r2 + c[1] * r2 * r2 + c[4] * r2 * r2 * r2;
      undistorted.emplace_back(x * f + 2 * c[2] * x * y + c[3] * (r2 + 2 * x * x),
                               y * f + 2 * c[3] * x * y + c[2] * (r2 + 2 * y * y));
      distorted.emplace_back(x, y);
    }
  }
  // Forward model, linear in (k1, k2, p1, p2):
  //   d - u = u (k1 r^2 + k2 r^4) + p1 (2 x y, r^2 + 2 y^2) + p2 (r^2 + 2 x^2, 2 x y),
  // with (x, y) = u and r^2 = |u|^2. Rows scaled by the focal lengths: residuals in pixels.
  const auto n = static_cast<Eigen::Index>(undistorted.size());
  Eigen::MatrixXd A(2 * n, 4);
  Eigen::VectorXd b(2 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector2d& uv = undistorted[static_cast<std::size_t>(i)];
    const double x = uv.x(), y = uv.y(), r2 = x * x + y * y;
    A.row(2 * i) << fx * x * r2, fx * x * r2 * r2, fx * 2 * x * y, fx * (r2 + 2 * x * x);
    A.row(2 * i + 1) << fy * y * r2, fy * y * r2 * r2, fy * (r2 + 2 * y * y), fy * 2 * x * y;
    const Eigen::Vector2d& d = distorted[static_cast<std::size_t>(i)];
    b(2 * i) = fx * (d.x() - x);
    b(2 * i + 1) = fy * (d.y() - y);
  }
  const Eigen::Vector4d k = A.colPivHouseholderQr().solve(b);
  const Eigen::VectorXd residual = A * k - b;
  ForwardDistortion out{k(0), k(1), k(2), k(3), 0, 0};
  double sum2 = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double e = std::hypot(residual(2 * i), residual(2 * i + 1));
    sum2 += e * e;
    out.max_px = std::max(out.max_px, e);
  }
  out.rms_px = std::sqrt(sum2 / static_cast<double>(n));
  return out;
}

std::string apply_d435i_factory_calibration(config::PosedConfig& config,
                                            drivers::camera::UsbTransport& usb) {
  config::CameraSection& cam = config.visible_camera;
  if (cam.intrinsics_source != "factory") {
    return "visible camera intrinsics from the configuration (visible_camera.intrinsics_source: " +
           cam.intrinsics_source + ")";
  }
  drivers::camera::D4xxStreamSizes sizes;
  sizes.colour_width = static_cast<std::uint32_t>(cam.width);
  sizes.colour_height = static_cast<std::uint32_t>(cam.height);
  drivers::camera::D4xxCalibration fallback;  // only `from_device` is read below
  const drivers::camera::D4xxCalibration c =
      drivers::camera::d4xx_calibration_or_fallback(usb, sizes, fallback);
  // The reader's one warning has said why; nothing more to log.
  if (!c.from_device) return {};
  const auto& k = c.colour.colour;
  const ForwardDistortion d = forward_from_inverse_brown_conrady(k.distortion, k.fx, k.fy, k.cx,
                                                                 k.cy, cam.width, cam.height);
  cam.fx = k.fx;
  cam.fy = k.fy;
  cam.cx = k.cx;
  cam.cy = k.cy;
  cam.k1 = d.k1;
  cam.k2 = d.k2;
  cam.p1 = d.p1;
  cam.p2 = d.p2;
  char line[320];
  std::snprintf(line, sizeof line,
                "visible camera intrinsics from the factory calibration (%s): fx %.3f fy %.3f cx "
                "%.3f cy %.3f px at %dx%d, distortion k1 %.5f k2 %.5f p1 %.5f p2 %.5f (fitted to "
                "the inverse Brown-Conrady model, rms %.3f px)",
                c.source.c_str(), cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height, cam.k1,
                cam.k2, cam.p1, cam.p2, d.rms_px);
  return line;
}

}  // namespace posed::pipeline
