#include "tools/sim/world.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace posed::sim {

void World::add_aabb(const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m,
                     std::uint32_t material) {
  Box b;
  b.center_m = 0.5 * (min_m + max_m);
  b.half_extent_m = 0.5 * (max_m - min_m);
  b.material = material;
  boxes.push_back(b);
}

void World::add_yawed(const Eigen::Vector3d& center_m, const Eigen::Vector3d& half_extent_m,
                      double yaw_rad, std::uint32_t material) {
  Box b;
  b.center_m = center_m;
  b.half_extent_m = half_extent_m;
  b.R_map_box = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  b.material = material;
  boxes.push_back(b);
}

std::optional<RayHit> intersect_box(const Box& box, const Eigen::Vector3d& origin_m,
                                    const Eigen::Vector3d& dir, double t_max_m) {
  const Eigen::Vector3d o = box.R_map_box.transpose() * (origin_m - box.center_m);
  const Eigen::Vector3d d = box.R_map_box.transpose() * dir;
  double t_near = -std::numeric_limits<double>::infinity();
  double t_far = std::numeric_limits<double>::infinity();
  int near_axis = 0, far_axis = 0;
  for (int a = 0; a < 3; ++a) {
    const double h = box.half_extent_m[a];
    if (std::abs(d[a]) < 1e-15) {
      if (o[a] < -h || o[a] > h) return std::nullopt;  // parallel and outside the slab
      continue;
    }
    const double inv = 1.0 / d[a];
    double t0 = (-h - o[a]) * inv, t1 = (h - o[a]) * inv;
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_near) {
      t_near = t0;
      near_axis = a;
    }
    if (t1 < t_far) {
      t_far = t1;
      far_axis = a;
    }
    if (t_near > t_far) return std::nullopt;
  }
  RayHit hit;
  hit.box = 0;
  if (t_near > 0.0) {
    if (t_near > t_max_m) return std::nullopt;
    hit.t_m = t_near;
    hit.face = static_cast<std::uint8_t>(2 * near_axis + (d[near_axis] < 0 ? 1 : 0));
  } else if (t_far > 0.0) {
    if (t_far > t_max_m) return std::nullopt;
    hit.t_m = t_far;  // inside the box (a tunnel's rock block around the sensor): its far wall
    hit.face = static_cast<std::uint8_t>(2 * far_axis + (d[far_axis] > 0 ? 1 : 0));
  } else {
    return std::nullopt;
  }
  return hit;
}

Eigen::Vector3d face_normal_map(const Box& box, std::uint8_t face) {
  const int axis = face / 2;
  const double sign = (face % 2 == 1) ? 1.0 : -1.0;
  return sign * box.R_map_box.col(axis);
}

Eigen::Vector2d face_uv_m(const Box& box, std::uint8_t face, const Eigen::Vector3d& p_map_m) {
  const Eigen::Vector3d q = box.R_map_box.transpose() * (p_map_m - box.center_m);
  // u, v along the two axes in the face's plane; offset by the box centre so neighbouring boxes
  // do not repeat the same pattern phase.
  const int axis = face / 2;
  const int ua = axis == 0 ? 1 : 0;
  const int va = axis == 2 ? 1 : 2;
  return {q[ua] + box.center_m[ua] * 0.37, q[va] + box.center_m[va] * 0.21};
}

namespace {

/// Integer hash (splitmix64 finaliser) → [0, 1).
double hash01(std::int64_t x, std::int64_t y, std::uint32_t seed) {
  std::uint64_t h =
      static_cast<std::uint64_t>(x) * 0x9E3779B97F4A7C15ull ^
      (static_cast<std::uint64_t>(y) + 0x632BE59BD9B4E019ull) * 0xBF58476D1CE4E5B9ull ^
      static_cast<std::uint64_t>(seed) * 0x94D049BB133111EBull;
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 27;
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

/// Bilinear value noise with cells of `cell_m` [m].
double value_noise(const Eigen::Vector2d& uv, double cell_m, std::uint32_t seed) {
  const double x = uv.x() / cell_m, y = uv.y() / cell_m;
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
  const double tx = x - fx, ty = y - fy;
  const double a = hash01(ix, iy, seed), b = hash01(ix + 1, iy, seed);
  const double c = hash01(ix, iy + 1, seed), d = hash01(ix + 1, iy + 1, seed);
  return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty;
}

}  // namespace

double texture_value(std::uint8_t texture, const Eigen::Vector2d& uv_m, std::uint32_t seed) {
  switch (texture) {
    case kTextureNoise:
      return 0.6 * value_noise(uv_m, 0.35, seed) + 0.4 * value_noise(uv_m, 0.07, seed + 1);
    case kTextureBricks: {
      const double row = std::floor(uv_m.y() / 0.075);
      const double x = uv_m.x() / 0.25 + 0.5 * std::fmod(std::abs(row), 2.0);
      const double fx = x - std::floor(x);
      const double fy = uv_m.y() / 0.075 - row;
      if (fx < 0.04 || fy < 0.13) return 0.9;  // mortar
      return 0.2 + 0.3 * hash01(static_cast<std::int64_t>(std::floor(x)),
                                static_cast<std::int64_t>(row), seed);
    }
    case kTextureStripes: {
      const double f = uv_m.x() - std::floor(uv_m.x());
      return f < 0.12 ? 1.0 : 0.0;
    }
    case kTextureChecker: {
      const auto cx = static_cast<std::int64_t>(std::floor(uv_m.x() / 0.2));
      const auto cy = static_cast<std::int64_t>(std::floor(uv_m.y() / 0.2));
      return ((cx + cy) & 1) != 0 ? 1.0 : 0.0;
    }
    default:
      return 0.5;
  }
}

}  // namespace posed::sim
