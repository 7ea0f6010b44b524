#include "tools/sim/trajectory.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace posed::sim {

PeriodicSpline2::PeriodicSpline2(const std::vector<Eigen::Vector2d>& points_m) : points_(points_m) {
  const std::size_t n = points_.size();
  knots_.assign(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double h = (points_[(i + 1) % n] - points_[i]).norm();
    knots_[i + 1] = knots_[i] + std::max(h, 1e-6);
  }
  // Periodic spline: h_{i-1} M_{i-1} + 2(h_{i-1} + h_i) M_i + h_i M_{i+1}
  //                  = 6 ((y_{i+1} - y_i)/h_i - (y_i - y_{i-1})/h_{i-1}), indices mod n.
  // Dense solve: waypoint counts are small (tens to a few hundred).
  const auto N = static_cast<Eigen::Index>(n);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(N, N);
  Eigen::MatrixXd rhs(N, 2);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t im = (i + n - 1) % n, ip = (i + 1) % n;
    const double hm = knots_[im + 1] - knots_[im];
    const double h = knots_[i + 1] - knots_[i];
    const auto I = static_cast<Eigen::Index>(i);
    A(I, static_cast<Eigen::Index>(im)) += hm;
    A(I, I) += 2.0 * (hm + h);
    A(I, static_cast<Eigen::Index>(ip)) += h;
    const Eigen::Vector2d r =
        6.0 * ((points_[ip] - points_[i]) / h - (points_[i] - points_[im]) / hm);
    rhs.row(I) = r.transpose();
  }
  const Eigen::MatrixXd M = A.partialPivLu().solve(rhs);
  second_.resize(n);
  for (std::size_t i = 0; i < n; ++i) second_[i] = M.row(static_cast<Eigen::Index>(i)).transpose();
}

void PeriodicSpline2::eval(double u, Eigen::Vector2d& p, Eigen::Vector2d& d1, Eigen::Vector2d& d2,
                           Eigen::Vector2d& d3) const {
  const double L = length();
  u = std::fmod(u, L);
  if (u < 0) u += L;
  const std::size_t n = points_.size();
  auto it = std::upper_bound(knots_.begin(), knots_.end(), u);
  std::size_t i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - knots_.begin() - 1, 0));
  if (i >= n) i = n - 1;
  const std::size_t j = (i + 1) % n;
  const double h = knots_[i + 1] - knots_[i];
  const double a = knots_[i + 1] - u, b = u - knots_[i];
  const Eigen::Vector2d& Mi = second_[i];
  const Eigen::Vector2d& Mj = second_[j];
  const Eigen::Vector2d ci = points_[i] / h - Mi * h / 6.0;
  const Eigen::Vector2d cj = points_[j] / h - Mj * h / 6.0;
  p = Mi * (a * a * a) / (6 * h) + Mj * (b * b * b) / (6 * h) + ci * a + cj * b;
  d1 = -Mi * (a * a) / (2 * h) + Mj * (b * b) / (2 * h) - ci + cj;
  d2 = Mi * a / h + Mj * b / h;
  d3 = (Mj - Mi) / h;
}

SpeedProfile::SpeedProfile(std::vector<SpeedRamp> ramps) : ramps_(std::move(ramps)) {
  double u = 0, prev_end = 0, prev_speed = 0;
  for (SpeedRamp& r : ramps_) {
    u += prev_speed * (r.start_s - prev_end);  // hold since the previous ramp ended
    r.u_start_m = u;
    u += r.duration_s * 0.5 * (r.from_mps + r.to_mps);  // ∫ smoothstep = 1/2
    prev_end = r.start_s + r.duration_s;
    prev_speed = r.to_mps;
    max_speed_ = std::max({max_speed_, r.from_mps, r.to_mps});
  }
}

void SpeedProfile::eval(double t, double& u, double& ud, double& udd, double& uddd) const {
  u = ud = udd = uddd = 0;
  if (ramps_.empty() || t <= ramps_.front().start_s) return;  // standing at u = 0
  auto it = std::upper_bound(ramps_.begin(), ramps_.end(), t,
                             [](double tt, const SpeedRamp& r) { return tt < r.start_s; });
  const SpeedRamp& r = *(it - 1);
  const double T = r.duration_s, dv = r.to_mps - r.from_mps;
  const double local = t - r.start_s;
  if (local < T) {
    const double s = local / T, s2 = s * s, s3 = s2 * s;
    // Quintic smoothstep S = 6s⁵ - 15s⁴ + 10s³ (zero first and second derivative at both ends).
    const double S = s3 * (10 - 15 * s + 6 * s2);
    const double Sd = 30 * s2 * (1 - 2 * s + s2);
    const double Sdd = 60 * s * (1 - 3 * s + 2 * s2);
    const double intS = s2 * s2 * (2.5 - 3 * s + s2);  // ∫0^s S
    u = r.u_start_m + T * (r.from_mps * s + dv * intS);
    ud = r.from_mps + dv * S;
    udd = dv * Sd / T;
    uddd = dv * Sdd / (T * T);
  } else {
    u = r.u_start_m + T * 0.5 * (r.from_mps + r.to_mps) + r.to_mps * (local - T);
    ud = r.to_mps;
  }
}

Trajectory::Trajectory(PeriodicSpline2 path, SpeedProfile speed, TrajectoryConfig config)
    : path_(std::move(path)), speed_(std::move(speed)), config_(std::move(config)) {}

namespace {

/// Σ A sin(ωt + φ) and its first two time derivatives.
void wobble(const std::vector<Wobble>& w, double t, double& x, double& xd, double& xdd) {
  x = xd = xdd = 0;
  for (const Wobble& k : w) {
    const double s = std::sin(k.omega_radps * t + k.phase_rad);
    const double c = std::cos(k.omega_radps * t + k.phase_rad);
    x += k.amplitude * s;
    xd += k.amplitude * k.omega_radps * c;
    xdd -= k.amplitude * k.omega_radps * k.omega_radps * s;
  }
}

}  // namespace

TrajectorySample Trajectory::at(double t) const {
  double u, ud, udd, uddd;
  speed_.eval(t, u, ud, udd, uddd);
  Eigen::Vector2d p, d1, d2, d3;
  path_.eval(u, p, d1, d2, d3);

  // Bumps scale with speed: m = u̇ / v_max (product rule for the derivatives).
  const double vmax = std::max(speed_.max_speed_mps(), 1e-9);
  const double m = ud / vmax, md = udd / vmax, mdd = uddd / vmax;
  auto scaled = [&](const std::vector<Wobble>& w, double& x, double& xd, double& xdd) {
    double b, bd, bdd;
    wobble(w, t, b, bd, bdd);
    x = m * b;
    xd = md * b + m * bd;
    xdd = mdd * b + 2 * md * bd + m * bdd;
  };
  double z, zd, zdd, roll, rolld, rolldd, pitch, pitchd, pitchdd;
  scaled(config_.z_wobble, z, zd, zdd);
  scaled(config_.roll_wobble, roll, rolld, rolldd);
  scaled(config_.pitch_wobble, pitch, pitchd, pitchdd);

  const double yaw = std::atan2(d1.y(), d1.x());
  const double yaw_u = (d1.x() * d2.y() - d1.y() * d2.x()) / d1.squaredNorm();
  const double yawd = yaw_u * ud;

  TrajectorySample s;
  s.p_map_base_m = {p.x(), p.y(), config_.base_height_m + z};
  s.v_map_mps = {d1.x() * ud, d1.y() * ud, zd};
  const Eigen::Vector2d a2 = d2 * ud * ud + d1 * udd;
  s.a_map_mps2 = {a2.x(), a2.y(), zdd};
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  s.q_map_base = Eigen::Quaterniond(R);
  const double sr = std::sin(roll), cr = std::cos(roll);
  const double sp = std::sin(pitch), cp = std::cos(pitch);
  // ZYX Euler rates to body rates.
  s.w_base_radps = {rolld - yawd * sp, pitchd * cr + yawd * cp * sr, -pitchd * sr + yawd * cp * cr};
  const Eigen::Vector3d g_map(0, 0, -config_.gravity_mps2);
  s.f_base_mps2 = R.transpose() * (s.a_map_mps2 - g_map);
  return s;
}

}  // namespace posed::sim
