#include "tools/sim/world.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

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
  return slab_hit({o.x(), o.y(), o.z()}, {d.x(), d.y(), d.z()},
                  {1.0 / d.x(), 1.0 / d.y(), 1.0 / d.z()},
                  {box.half_extent_m.x(), box.half_extent_m.y(), box.half_extent_m.z()}, t_max_m);
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

/// Integer hash of a lattice point (a 32-bit finaliser, murmur3's) → [0, 1), for the bricks.
inline double hash01(std::int32_t x, std::int32_t y, std::uint32_t seed) {
  std::uint32_t h = seed * 0x9E3779B1u ^ static_cast<std::uint32_t>(x) * 0x85EBCA77u ^
                    static_cast<std::uint32_t>(y) * 0xC2B2AE3Du;
  h ^= h >> 16;
  h *= 0x85EBCA6Bu;
  h ^= h >> 13;
  h *= 0xC2B2AE35u;
  h ^= h >> 16;
  return static_cast<double>(h) * (1.0 / 4294967296.0);
}

/// Random values on the integer lattice for value noise, evaluated ~10 million times per
/// simulated second (four corners, two octaves, every textured pixel): two fixed permutations
/// of 4096 entries hashed by XOR pick one of 4096 values, three table reads per point instead
/// of a hash. The pattern repeats every 4096 cells (287 m of the 7 cm grain), far beyond what a
/// camera resolves; `seed` (the box) shifts it so that boxes do not share one pattern.
class Lattice {
 public:
  static const Lattice& get() {
    static const Lattice lattice;
    return lattice;
  }
  double at(std::int32_t x, std::int32_t y, std::uint32_t seed) const {
    const auto ix = static_cast<std::uint32_t>(x) + seed * 1237u;
    const auto iy = static_cast<std::uint32_t>(y) + seed * 2417u;
    return value_[static_cast<std::size_t>(px_[ix & kMask] ^ py_[iy & kMask])];
  }

 private:
  static constexpr std::uint32_t kSize = 4096, kMask = kSize - 1;
  Lattice() {
    std::mt19937 rng(0x1A77'1CE5u);
    std::iota(px_.begin(), px_.end(), std::uint16_t{0});
    std::iota(py_.begin(), py_.end(), std::uint16_t{0});
    std::shuffle(px_.begin(), px_.end(), rng);
    std::shuffle(py_.begin(), py_.end(), rng);
    for (float& v : value_) v = static_cast<float>(static_cast<double>(rng()) / 4294967296.0);
  }
  std::array<std::uint16_t, kSize> px_{}, py_{};
  std::array<float, kSize> value_{};
};

/// floor() for texture coordinates (|x| < 2^31), without a libm call.
inline std::int32_t floor_i(double x) {
  const auto i = static_cast<std::int32_t>(x);
  return x < static_cast<double>(i) ? i - 1 : i;
}

/// Bilinear value noise with cells of 1/`per_m` [m].
double value_noise(const Eigen::Vector2d& uv, double per_m, std::uint32_t seed) {
  const double x = uv.x() * per_m, y = uv.y() * per_m;
  const std::int32_t ix = floor_i(x), iy = floor_i(y);
  const double tx = x - ix, ty = y - iy;
  const Lattice& L = Lattice::get();
  const double a = L.at(ix, iy, seed), b = L.at(ix + 1, iy, seed);
  const double c = L.at(ix, iy + 1, seed), d = L.at(ix + 1, iy + 1, seed);
  return (a + (b - a) * tx) * (1 - ty) + (c + (d - c) * tx) * ty;
}

}  // namespace

double texture_value(std::uint8_t texture, const Eigen::Vector2d& uv_m, std::uint32_t seed) {
  switch (texture) {
    case kTextureNoise:
      // blotches of 0.35 m and grain of 0.07 m
      return 0.6 * value_noise(uv_m, 1.0 / 0.35, seed) +
             0.4 * value_noise(uv_m, 1.0 / 0.07, seed + 1);
    case kTextureBricks: {
      const double rows = uv_m.y() / 0.075;
      const std::int32_t row = floor_i(rows);
      const double x = uv_m.x() / 0.25 + ((row & 1) != 0 ? 0.5 : 0.0);
      const std::int32_t column = floor_i(x);
      const double fx = x - column, fy = rows - row;
      if (fx < 0.04 || fy < 0.13) return 0.9;  // mortar
      return 0.2 + 0.3 * hash01(column, row, seed);
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
