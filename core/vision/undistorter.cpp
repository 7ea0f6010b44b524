#include "core/vision/undistorter.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace posed::vision {

Undistorter::Undistorter(const PinholeCamera& camera) : camera_(camera) {
  const std::size_t n =
      static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  x_.resize(n);
  y_.resize(n);
  for (int r = 0; r < camera.height; ++r) {
    for (int c = 0; c < camera.width; ++c) {
      Eigen::Vector2d xy;
      if (!camera.normalised_from_pixel(Eigen::Vector2d(c, r), xy)) {
        xy.setConstant(std::numeric_limits<double>::quiet_NaN());
      }
      const std::size_t i = static_cast<std::size_t>(r) * static_cast<std::size_t>(camera.width) +
                            static_cast<std::size_t>(c);
      x_[i] = xy.x();
      y_[i] = xy.y();
    }
  }
}

Eigen::Vector2d Undistorter::normalised(const Eigen::Vector2d& pixel) const {
  const double u = pixel.x(), v = pixel.y();
  if (!(u >= 0 && v >= 0 && u <= camera_.width - 1 && v <= camera_.height - 1)) {
    return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  const int c = std::min(static_cast<int>(u), camera_.width - 2);
  const int r = std::min(static_cast<int>(v), camera_.height - 2);
  const double a = u - c, b = v - r;
  Eigen::Vector2d xy = (1 - a) * (1 - b) * at(c, r) + a * (1 - b) * at(c + 1, r) +
                       (1 - a) * b * at(c, r + 1) + a * b * at(c + 1, r + 1);
  // One Gauss-Newton step on distort(xy) = target (the Jacobian of PinholeCamera::distort).
  const PinholeCamera& k = camera_;
  const Eigen::Vector2d target((u - k.cx) / k.fx, (v - k.cy) / k.fy);
  const double x = xy.x(), y = xy.y(), r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k.k1 + k.k2 * r2);
  const double dradial = k.k1 + 2 * k.k2 * r2;
  Eigen::Matrix2d J;
  J(0, 0) = radial + 2 * x * x * dradial + 2 * k.p1 * y + 6 * k.p2 * x;
  J(0, 1) = 2 * x * y * dradial + 2 * k.p1 * x + 2 * k.p2 * y;
  J(1, 0) = J(0, 1);
  J(1, 1) = radial + 2 * y * y * dradial + 6 * k.p1 * y + 2 * k.p2 * x;
  xy -= J.inverse() * (k.distort(xy) - target);
  return xy;
}

}  // namespace posed::vision
