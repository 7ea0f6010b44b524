#include "core/sim/circle_motion.hpp"

#include <algorithm>
#include <cmath>

namespace posed::sim {

MotionSample CircleMotion::at(Duration t) const {
  const double tau = std::max(0.0, t.seconds() - c_.static_s);
  const double V = c_.speed_mps;
  const double Tr = c_.ramp_s;
  // Arc length s, speed v and tangential acceleration a_t. During the ramp v = V*(3x^2 - 2x^3)
  // with x = tau/Tr, so v and a_t are continuous (no jerk spike at either end).
  double s = 0, v = 0, a_t = 0;
  if (tau < Tr) {
    const double x = tau / Tr;
    s = V * Tr * (x * x * x - 0.5 * x * x * x * x);
    v = V * (3 * x * x - 2 * x * x * x);
    a_t = V * (6 * x - 6 * x * x) / Tr;
  } else {
    s = 0.5 * V * Tr + V * (tau - Tr);
    v = V;
    a_t = 0;
  }
  const double R = c_.radius_m;
  const double yaw = s / R;
  MotionSample m;
  m.p_map_base_m = Eigen::Vector3d(R * std::sin(yaw), R * (1 - std::cos(yaw)), 0);
  m.q_map_base = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  m.v_map_mps = Eigen::Vector3d(v * std::cos(yaw), v * std::sin(yaw), 0);
  m.w_base_radps = Eigen::Vector3d(0, 0, v / R);
  // Body frame: tangential along x, centripetal toward the centre (+y, left), gravity reaction +z.
  m.f_base_mps2 = Eigen::Vector3d(a_t, v * v / R, c_.gravity_mps2);
  return m;
}

}  // namespace posed::sim
