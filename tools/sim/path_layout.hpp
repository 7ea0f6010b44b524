#pragma once
// Placing things beside a closed path (the scenarios' loops, scenarios.cpp and campus.cpp): the
// path's frame at a point, points along it, and whether a box keeps its distance from it.

#include <Eigen/Core>
#include <vector>

#include "tools/sim/trajectory.hpp"

namespace posed::sim {

/// Points along the path every `step_m`, for clearance checks.
std::vector<Eigen::Vector2d> sample_path(const PeriodicSpline2& path, double step_m);

/// Whether a yawed box footprint (centre `c`, half sizes `hx`, `hy` [m]) stays `clearance_m`
/// away from every path sample.
bool clear_of_path(const std::vector<Eigen::Vector2d>& samples, const Eigen::Vector2d& c, double hx,
                   double hy, double yaw, double clearance_m);

/// Frame of the path at u: point, unit tangent, left normal, heading.
struct PathFrame {
  Eigen::Vector2d p, t, n;
  double yaw;
};
PathFrame path_frame(const PeriodicSpline2& path, double u);

}  // namespace posed::sim
