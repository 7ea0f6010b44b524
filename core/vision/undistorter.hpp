#pragma once
// Fast, exact pixel -> normalised coordinates for one camera: the undistorted coordinates of
// every pixel are computed once (Gauss-Newton, PinholeCamera::normalised_from_pixel), a query
// interpolates them bilinearly and then takes one Gauss-Newton step on the distortion model,
// which brings the ~1e-6 interpolation error down to rounding. The tracker undistorts every
// feature of every frame; this costs ~50 ns a point instead of several microseconds.

#include <Eigen/Core>
#include <vector>

#include "core/vision/pinhole_camera.hpp"

namespace posed::vision {

class Undistorter {
 public:
  explicit Undistorter(const PinholeCamera& camera);

  /// Normalised undistorted (x/z, y/z) of `pixel` [px]; NaN outside [0, W-1] x [0, H-1].
  Eigen::Vector2d normalised(const Eigen::Vector2d& pixel) const;

  /// The table's entry for integer pixel (c, r): the undistorted coordinates of its centre.
  Eigen::Vector2d at(int c, int r) const {
    const std::size_t i = static_cast<std::size_t>(r) * static_cast<std::size_t>(camera_.width) +
                          static_cast<std::size_t>(c);
    return {x_[i], y_[i]};
  }

  const PinholeCamera& camera() const { return camera_; }

 private:
  PinholeCamera camera_;
  std::vector<double> x_, y_;  // per pixel, row-major
};

}  // namespace posed::vision
