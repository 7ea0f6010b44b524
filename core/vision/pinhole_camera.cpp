#include "core/vision/pinhole_camera.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace posed::vision {

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

Eigen::Vector2d PinholeCamera::distort(const Eigen::Vector2d& xy) const {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + k2 * r2);
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

Eigen::Vector2d PinholeCamera::pixel_from_normalised(const Eigen::Vector2d& xy) const {
  const Eigen::Vector2d d = distort(xy);
  return {fx * d.x() + cx, fy * d.y() + cy};
}

bool PinholeCamera::project(const Eigen::Vector3d& p_cam, Eigen::Vector2d& pixel) const {
  if (!(p_cam.z() > 0)) return false;
  pixel = pixel_from_normalised(p_cam.head<2>() / p_cam.z());
  return true;
}

bool PinholeCamera::normalised_from_pixel(const Eigen::Vector2d& pixel, Eigen::Vector2d& xy) const {
  const Eigen::Vector2d target((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  xy = target;  // the undistorted point is near the distorted one for any sane lens
  for (int iteration = 0; iteration < 30; ++iteration) {
    const double x = xy.x(), y = xy.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k1 + k2 * r2);
    const double dradial_dr2 = k1 + 2 * k2 * r2;
    const Eigen::Vector2d residual = distort(xy) - target;
    // Jacobian of distort() w.r.t. (x, y).
    Eigen::Matrix2d J;
    J(0, 0) = radial + 2 * x * x * dradial_dr2 + 2 * p1 * y + 6 * p2 * x;
    J(0, 1) = 2 * x * y * dradial_dr2 + 2 * p1 * x + 2 * p2 * y;
    J(1, 0) = 2 * x * y * dradial_dr2 + 2 * p1 * x + 2 * p2 * y;
    J(1, 1) = radial + 2 * y * y * dradial_dr2 + 6 * p1 * y + 2 * p2 * x;
    const Eigen::Vector2d step = J.partialPivLu().solve(residual);
    if (!step.allFinite()) return false;
    xy -= step;
    if (step.norm() * std::max(fx, fy) < 1e-10) break;
  }
  const Eigen::Vector2d d = distort(xy);
  const double error_px = std::hypot((d.x() - target.x()) * fx, (d.y() - target.y()) * fy);
  return std::isfinite(error_px) && error_px < 1e-9;
}

double PinholeCamera::horizontal_fov_rad() const {
  return 2.0 * std::atan(static_cast<double>(width) / (2.0 * fx));
}

double PinholeCamera::vertical_fov_rad() const {
  return 2.0 * std::atan(static_cast<double>(height) / (2.0 * fy));
}

}  // namespace posed::vision
