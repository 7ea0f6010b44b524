#include "core/vision/depth_associator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <numbers>

namespace posed::vision {
namespace {

/// atan(t) to 2e-8 rad: Abramowitz & Stegun 4.4.49 on [-1, 1], atan(t) = pi/2 - atan(1/t)
/// beyond. Twice for each of ~10k points per frame, where std::atan2 cost a third of the step.
double fast_atan(double t) {
  const bool outside = std::abs(t) > 1.0;
  const double u = outside ? 1.0 / t : t, u2 = u * u;
  const double p =
      u * (1.0 + u2 * (-0.3333314528 +
                       u2 * (0.1999355085 +
                             u2 * (-0.1420889944 +
                                   u2 * (0.1065626393 +
                                         u2 * (-0.0752896400 +
                                               u2 * (0.0429096138 + u2 * (-0.0161657367 +
                                                                          u2 * 0.0028662257))))))));
  if (!outside) return p;
  return (t > 0 ? std::numbers::pi / 2 : -std::numbers::pi / 2) - p;
}

/// Polar coordinates of a direction in front of the camera (z > 0): azimuth atan2(x, z),
/// elevation atan2(y, hypot(x, z)) [rad].
Eigen::Vector2f polar_of(double x, double y, double z) {
  const double horizontal = std::sqrt(x * x + z * z);
  return {static_cast<float>(fast_atan(x / z)), static_cast<float>(fast_atan(y / horizontal))};
}

}  // namespace

DepthAssociator::DepthAssociator(const DepthConfig& config, const PinholeCamera& camera)
    : config_(config) {
  // The image's field of view in polar coordinates: the undistorted rays of its border pixels.
  azimuth_min_ = elevation_min_ = 1e9;
  azimuth_max_ = elevation_max_ = -1e9;
  const auto include = [&](double u, double v) {
    Eigen::Vector2d xy;
    if (!camera.normalised_from_pixel(Eigen::Vector2d(u, v), xy)) return;
    const Eigen::Vector2f p = polar_of(xy.x(), xy.y(), 1.0);
    azimuth_min_ = std::min(azimuth_min_, static_cast<double>(p.x()));
    azimuth_max_ = std::max(azimuth_max_, static_cast<double>(p.x()));
    elevation_min_ = std::min(elevation_min_, static_cast<double>(p.y()));
    elevation_max_ = std::max(elevation_max_, static_cast<double>(p.y()));
  };
  const double w = camera.width - 1.0, h = camera.height - 1.0;
  for (double u = 0; u <= w; u += 4) {
    include(u, 0);
    include(u, h);
  }
  for (double v = 0; v <= h; v += 4) {
    include(0, v);
    include(w, v);
  }
  include(w, 0);
  include(w, h);
  include(0, h);
  const double m = config_.fov_margin_rad;
  const double half_pi = 1.5;  // keep the bounds inside (-86, 86) deg so tan() stays finite
  azimuth_min_ = std::max(azimuth_min_ - m, -half_pi);
  azimuth_max_ = std::min(azimuth_max_ + m, half_pi);
  elevation_min_ = std::max(elevation_min_ - m, -half_pi);
  elevation_max_ = std::min(elevation_max_ + m, half_pi);
  // Superset on the normalised plane: azimuth = atan(x/z) exactly; |y/z| = tan(elevation)
  // sqrt(1 + (x/z)^2) grows with |x/z|, so bound it at the widest x/z.
  x_min_ = std::tan(azimuth_min_);
  x_max_ = std::tan(azimuth_max_);
  const double widest = std::sqrt(1.0 + std::max(x_min_ * x_min_, x_max_ * x_max_));
  y_min_ = std::tan(elevation_min_) * (elevation_min_ < 0 ? widest : 1.0);
  y_max_ = std::tan(elevation_max_) * (elevation_max_ > 0 ? widest : 1.0);
  cos_elevation_bound_ = std::cos(std::max(std::abs(elevation_min_), std::abs(elevation_max_)));
  sin_half_neighbour_angle_ = std::sin(config_.max_neighbour_angle_rad / 2);
  const double cell = std::max(config_.cell_rad, 1e-5);
  cells_x_ = std::max(1, static_cast<int>(std::ceil((azimuth_max_ - azimuth_min_) / cell)));
  cells_y_ = std::max(1, static_cast<int>(std::ceil((elevation_max_ - elevation_min_) / cell)));
  cell_best_.assign(static_cast<std::size_t>(cells_x_) * static_cast<std::size_t>(cells_y_), -1);
  cell_range_.assign(cell_best_.size(), 0.f);
}

DepthAssociator::~DepthAssociator() = default;

void DepthAssociator::set_points(std::span<const Eigen::Vector3f> p_cam_m) {
  candidates_.clear();
  candidate_polar_.clear();
  std::fill(cell_best_.begin(), cell_best_.end(), -1);
  const float min_r2 = static_cast<float>(config_.min_range_m * config_.min_range_m);
  const float max_r2 = static_cast<float>(config_.max_range_m * config_.max_range_m);
  const double cell = std::max(config_.cell_rad, 1e-5);
  for (const Eigen::Vector3f& p : p_cam_m) {
    // Cheap cull first (most of a 360 deg scan is behind or beside the camera).
    if (!(p.z() > 0.f)) continue;
    const float x = p.x() / p.z(), y = p.y() / p.z();
    if (x < x_min_ || x > x_max_ || y < y_min_ || y > y_max_) continue;
    const float r2 = p.squaredNorm();
    if (r2 < min_r2 || r2 > max_r2) continue;
    const Eigen::Vector2f polar = polar_of(p.x(), p.y(), p.z());
    if (polar.x() < azimuth_min_ || polar.x() > azimuth_max_ || polar.y() < elevation_min_ ||
        polar.y() > elevation_max_) {
      continue;
    }
    const int cx = std::min(cells_x_ - 1, static_cast<int>((polar.x() - azimuth_min_) / cell));
    const int cy = std::min(cells_y_ - 1, static_cast<int>((polar.y() - elevation_min_) / cell));
    const std::size_t c = static_cast<std::size_t>(cy) * static_cast<std::size_t>(cells_x_) +
                          static_cast<std::size_t>(cx);
    // Nearest point per cell: a surface hides what is behind it. Ties keep the first point.
    if (cell_best_[c] >= 0 && cell_range_[c] <= r2) continue;
    if (cell_best_[c] < 0) {
      cell_best_[c] = static_cast<std::int32_t>(candidates_.size());
      candidates_.push_back(p);
      candidate_polar_.push_back(polar);
    } else {
      const auto i = static_cast<std::size_t>(cell_best_[c]);
      candidates_[i] = p;
      candidate_polar_[i] = polar;
    }
    cell_range_[c] = r2;
  }
  // In cell order (deterministic, and neighbouring keys stay close in memory); each cell now
  // names its point in points_.
  points_.clear();
  polar_.clear();
  for (std::int32_t& i : cell_best_) {
    if (i < 0) continue;
    const auto point = static_cast<std::int32_t>(points_.size());
    points_.push_back(candidates_[static_cast<std::size_t>(i)]);
    polar_.push_back(candidate_polar_[static_cast<std::size_t>(i)]);
    i = point;
  }
}

std::size_t DepthAssociator::nearest(const Eigen::Vector2f& key, double max_key_distance_rad,
                                     std::size_t wanted, std::uint32_t* index,
                                     float* distance_sq) const {
  if (wanted == 0 || points_.empty() || !key.allFinite()) return 0;
  const double cell = std::max(config_.cell_rad, 1e-5);
  // Clamped as a double first: a key far outside the grid must not overflow the int.
  const auto cell_of = [](double offset, int cells) {
    return static_cast<int>(std::clamp(std::floor(offset), 0.0, static_cast<double>(cells - 1)));
  };
  const int qx = cell_of((key.x() - azimuth_min_) / cell, cells_x_);
  const int qy = cell_of((key.y() - elevation_min_) / cell, cells_y_);
  const float max_sq = static_cast<float>(max_key_distance_rad * max_key_distance_rad);
  std::size_t found = 0;
  // Kept sorted by (distance, index): ties go to the earlier point, whatever the visiting order.
  const auto offer = [&](std::uint32_t i) {
    const Eigen::Vector2f& p = polar_[i];
    // As a kd-tree over float keys computes it, so the order is the same.
    const float dx = key.x() - p.x();
    float d = dx * dx;
    const float dy = key.y() - p.y();
    d += dy * dy;
    if (d > max_sq) return;
    const auto before = [&](std::size_t k) {
      return distance_sq[k] < d || (distance_sq[k] == d && index[k] < i);
    };
    if (found == wanted && before(found - 1)) return;
    std::size_t k = found < wanted ? found++ : wanted - 1;
    for (; k > 0 && !before(k - 1); --k) {
      distance_sq[k] = distance_sq[k - 1];
      index[k] = index[k - 1];
    }
    distance_sq[k] = d;
    index[k] = i;
  };
  const auto visit = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= cells_x_ || y >= cells_y_) return;
    const std::int32_t i =
        cell_best_[static_cast<std::size_t>(y) * static_cast<std::size_t>(cells_x_) +
                   static_cast<std::size_t>(x)];
    if (i >= 0) offer(static_cast<std::uint32_t>(i));
  };
  // Square rings of cells around the key's cell, nearest first. A point in ring r + 1 or beyond
  // lies at least r cells' width from the key in azimuth or elevation (less a margin for the
  // keys' float rounding), so once the wanted points are nearer than that, or that is beyond the
  // radius, no further ring can change the answer.
  const int rings = std::max({qx, cells_x_ - 1 - qx, qy, cells_y_ - 1 - qy});
  for (int r = 0; r <= rings; ++r) {
    for (int x = qx - r; x <= qx + r; ++x) {
      visit(x, qy - r);
      if (r > 0) visit(x, qy + r);
    }
    for (int y = qy - r + 1; y <= qy + r - 1; ++y) {
      visit(qx - r, y);
      visit(qx + r, y);
    }
    const double gap = static_cast<double>(r) * cell - 1e-5;
    if (gap > max_key_distance_rad) break;
    if (found == wanted && gap > 0 && static_cast<double>(distance_sq[found - 1]) < gap * gap)
      break;
  }
  return found;
}

DepthResult DepthAssociator::depth(const Eigen::Vector2d& normalised) const {
  DepthResult result;
  if (points_.size() < 3) return result;
  const Eigen::Vector3d ray = Eigen::Vector3d(normalised.x(), normalised.y(), 1.0).normalized();
  const Eigen::Vector2f key = polar_of(ray.x(), ray.y(), ray.z());
  constexpr std::size_t kMaxCandidates = 32;
  const std::size_t wanted = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::max(config_.candidates, 3)), 3, kMaxCandidates);
  std::array<std::uint32_t, kMaxCandidates> index{};
  std::array<float, kMaxCandidates> distance_sq{};
  // Only points within max_neighbour_angle_rad of the ray are ever used (the first three must
  // be, and the search for a third point stops at the first that is not), so the search looks no
  // further than the polar-key distance such a point can have. Between bearings at elevations
  // e1, e2 a key distance d means an angle theta with sin(theta / 2) >= sqrt(cos e1 cos e2)
  // sin(d / 2) (haversine, and sin(u) / u falling on [0, pi/2]): beyond that radius every
  // point is further than the allowed angle.
  const double cos_elevations =
      std::sqrt(cos_elevation_bound_ * std::cos(std::abs(static_cast<double>(key.y()))));
  const double sin_half = sin_half_neighbour_angle_ / cos_elevations;
  const double radius = sin_half < 1.0 ? 2 * std::asin(sin_half) * (1 + 1e-4) + 1e-6
                                       : std::numeric_limits<double>::infinity();
  const std::size_t found = nearest(key, radius, wanted, index.data(), distance_sq.data());
  if (found < 3) {
    result.status = DepthStatus::kTooFar;
    return result;
  }

  // Candidates nearest first; each must lie within the search radius (true angle, not the
  // polar-key distance). The first two are the paper's nearest two.
  const double cos_max = std::cos(config_.max_neighbour_angle_rad);
  const auto within = [&](std::size_t k) {
    const Eigen::Vector3d p = points_[index[k]].cast<double>();
    return p.dot(ray) >= cos_max * p.norm();
  };
  for (std::size_t k = 0; k < 3; ++k) {
    if (!within(k)) {
      result.status = DepthStatus::kTooFar;
      return result;
    }
  }
  const Eigen::Vector3d P0 = points_[index[0]].cast<double>();
  const Eigen::Vector3d P1 = points_[index[1]].cast<double>();
  // 2 area / longest side^2 of a triangle: 0 collinear, sqrt(3)/2 equilateral.
  const auto shape = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c) {
    const double longest =
        std::max({(a - b).squaredNorm(), (a - c).squaredNorm(), (b - c).squaredNorm()});
    return longest > 0 ? (b - a).cross(c - a).norm() / longest : 0.0;
  };
  const auto span_of = [&](const std::array<Eigen::Vector3d, 3>& T) {
    if (config_.span == SpanMeasure::kRangeSpread) {
      const double a = T[0].norm(), b = T[1].norm(), c = T[2].norm();
      return std::max({a, b, c}) - std::min({a, b, c});
    }
    return std::max({(T[0] - T[1]).norm(), (T[0] - T[2]).norm(), (T[1] - T[2]).norm()});
  };
  // The paper's test on the 3 nearest first: a depth edge among them rejects the feature, even
  // if a replacement third point would hide it.
  std::array<Eigen::Vector3d, 3> P = {P0, P1, points_[index[2]].cast<double>()};
  result.span_m = span_of(P);
  if (result.span_m > config_.max_span_m) {
    result.status = DepthStatus::kSpan;
    return result;
  }
  if (shape(P[0], P[1], P[2]) < config_.min_triangle_shape) {
    for (std::size_t k = 3; k < found && within(k); ++k) {
      const Eigen::Vector3d candidate = points_[index[k]].cast<double>();
      if (shape(P0, P1, candidate) < config_.min_triangle_shape) continue;
      P[2] = candidate;
      result.span_m = span_of(P);
      if (result.span_m > config_.max_span_m) {
        result.status = DepthStatus::kSpan;
        return result;
      }
      break;
    }
  }
  std::array<double, 3> range{};
  for (std::size_t k = 0; k < 3; ++k) range[k] = P[k].norm();
  const double r_min = *std::min_element(range.begin(), range.end());
  const double r_max = *std::max_element(range.begin(), range.end());
  const Eigen::Vector3d n = (P[1] - P[0]).cross(P[2] - P[0]);
  const double n_norm = n.norm();
  if (shape(P[0], P[1], P[2]) < config_.min_triangle_shape ||
      std::abs(n.dot(ray)) < std::sin(config_.min_incidence_rad) * n_norm) {
    result.status = DepthStatus::kDegenerate;
    return result;
  }
  const double s = n.dot(P[0]) / n.dot(ray);  // range along the unit ray [m]
  if (s < r_min - config_.max_extrapolation_m || s > r_max + config_.max_extrapolation_m) {
    result.status = DepthStatus::kOutsideRange;
    return result;
  }
  result.depth_m = s * ray.z();
  result.status = DepthStatus::kOk;
  return result;
}

}  // namespace posed::vision
