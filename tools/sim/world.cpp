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

TextureFootprint pixel_footprint(const Box& box, std::uint8_t face, const Eigen::Vector3d& dir_map,
                                 double range_m, double pixel_angle_rad) {
  const int axis = face / 2;
  const int ua = axis == 0 ? 1 : 0;
  const int va = axis == 2 ? 1 : 2;
  // A ray tilted by theta from the normal towards an in-plane axis e spreads the pixel along e by
  // 1/cos(theta) = sqrt(1 + tan^2): tan = (e.d)/(n.d). Grazing rays are capped at 1/0.02.
  const double n_d = std::max(std::abs(box.R_map_box.col(axis).dot(dir_map)), 0.02);
  const double tan_u = box.R_map_box.col(ua).dot(dir_map) / n_d;
  const double tan_v = box.R_map_box.col(va).dot(dir_map) / n_d;
  const double pitch_m = range_m * pixel_angle_rad;
  return {pitch_m * std::sqrt(1.0 + tan_u * tan_u), pitch_m * std::sqrt(1.0 + tan_v * tan_v)};
}

namespace {

/// Integral from 0 to x of a periodic pulse that is 1 on [0, duty) of each period of 1.
inline double pulse_integral(double x, double duty) {
  const double cell = std::floor(x);
  return cell * duty + std::min(x - cell, duty);
}

/// The pulse (period 1, 1 on [0, duty)) averaged over [x - w/2, x + w/2]; point sample for a
/// footprint far below the period.
inline double pulse_box(double x, double duty, double w) {
  if (w < 1e-4) return x - std::floor(x) < duty ? 1.0 : 0.0;
  return (pulse_integral(x + 0.5 * w, duty) - pulse_integral(x - 0.5 * w, duty)) / w;
}

/// How much of a random pattern of `cell`-sized cells survives averaging over a footprint: the
/// standard deviation of the mean of the (u/cell)(v/cell) cells it covers, relative to one.
inline double fade(double cell, const TextureFootprint& f) {
  return std::sqrt(std::min(1.0, cell / std::max(f.u_m, 1e-9)) *
                   std::min(1.0, cell / std::max(f.v_m, 1e-9)));
}

}  // namespace

double texture_value(std::uint8_t texture, const Eigen::Vector2d& uv_m, std::uint32_t seed,
                     const TextureFootprint& f) {
  switch (texture) {
    case kTextureNoise:
      return 0.5 + 0.6 * fade(0.35, f) * (value_noise(uv_m, 1.0 / 0.35, seed) - 0.5) +
             0.4 * fade(0.07, f) * (value_noise(uv_m, 1.0 / 0.07, seed + 1) - 0.5);
    case kTextureBricks: {
      constexpr double kRow = 0.075, kBrick = 0.25;
      const double rows = uv_m.y() / kRow;
      const std::int32_t row = floor_i(rows);
      const double x = uv_m.x() / kBrick + ((row & 1) != 0 ? 0.5 : 0.0);
      const double half_u = 0.5 * f.u_m / kBrick, half_v = 0.5 * f.v_m / kRow;
      // Bed joints (13 % of a course): exact. Head joints (4 % of a brick): exact over the part
      // of the footprint in this course and in the neighbouring ones, whose joints are staggered
      // by half a brick; their mean beyond a course.
      const double bed = pulse_box(rows, 0.13, 2 * half_v);
      double head = 0.04;
      if (half_v < 1) {
        const double in_row =
            half_v < 1e-9
                ? 1.0
                : (std::min(rows + half_v, row + 1.0) - std::max(rows - half_v, 1.0 * row)) /
                      (2 * half_v);
        head = in_row * pulse_box(x, 0.04, 2 * half_u) +
               (1 - in_row) * pulse_box(x + 0.5, 0.04, 2 * half_u);
      }
      const double mortar = 1 - (1 - bed) * (1 - head);
      // Brick colours: this course's bricks weighted by their share of the footprint, fading to
      // the mean as the footprint covers many.
      const std::int32_t first = floor_i(x - half_u), last = floor_i(x + half_u);
      double brick = 0.35;
      if (last - first <= 1) {
        // The brick faces (a cell minus its head joint) the footprint covers in this course.
        const auto face = [&](std::int32_t c) {
          if (half_u < 1e-9) return c == floor_i(x) ? 1.0 : 0.0;
          return std::max(0.0, std::min(x + half_u, c + 1.0) - std::max(x - half_u, c + 0.04));
        };
        const double a_first = face(first), a_last = last == first ? 0.0 : face(last);
        const double colour =
            a_first + a_last > 0
                ? (a_first * hash01(first, row, seed) + a_last * hash01(last, row, seed)) /
                      (a_first + a_last)
                : 0.5;
        brick += fade(kRow, {0, f.v_m}) * 0.3 * (colour - 0.5);
      } else {
        brick += fade(kBrick, {f.u_m, f.v_m * kBrick / kRow}) * 0.3 *
                 (hash01(floor_i(x), row, seed) - 0.5);
      }
      return mortar * 0.9 + (1 - mortar) * brick;
    }
    case kTextureStripes:
      return pulse_box(uv_m.x(), 0.12, f.u_m);
    case kTextureChecker: {
      // +-1 square waves of period 0.4 m in u and v; the checker is their product, and a box
      // filter of a product of functions of u and of v is the product of their filtered values.
      const auto square = [](double x, double w) {
        return 1.0 - 2.0 * pulse_box(x / 0.4, 0.5, w / 0.4);
      };
      return 0.5 * (1.0 - square(uv_m.x(), f.u_m) * square(uv_m.y(), f.v_m));
    }
    default:
      return 0.5;
  }
}

}  // namespace posed::sim
