#include "tools/sim/path_layout.hpp"

#include <algorithm>
#include <cmath>

namespace posed::sim {

std::vector<Eigen::Vector2d> sample_path(const PeriodicSpline2& path, double step_m) {
  std::vector<Eigen::Vector2d> out;
  Eigen::Vector2d p, d1, d2, d3;
  for (double u = 0; u < path.length(); u += step_m) {
    path.eval(u, p, d1, d2, d3);
    out.push_back(p);
  }
  return out;
}

bool clear_of_path(const std::vector<Eigen::Vector2d>& samples, const Eigen::Vector2d& c, double hx,
                   double hy, double yaw, double clearance_m) {
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  for (const Eigen::Vector2d& s : samples) {
    const Eigen::Vector2d d = s - c;
    const double x = cy * d.x() + sy * d.y(), y = -sy * d.x() + cy * d.y();
    const double dx = std::max(std::abs(x) - hx, 0.0), dy = std::max(std::abs(y) - hy, 0.0);
    if (dx * dx + dy * dy < clearance_m * clearance_m) return false;
  }
  return true;
}

PathFrame path_frame(const PeriodicSpline2& path, double u) {
  Eigen::Vector2d p, d1, d2, d3;
  path.eval(u, p, d1, d2, d3);
  const Eigen::Vector2d t = d1.normalized();
  return {p, t, {-t.y(), t.x()}, std::atan2(t.y(), t.x())};
}

}  // namespace posed::sim
