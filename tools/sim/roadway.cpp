#include "tools/sim/roadway.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "tools/sim/scenario_random.hpp"

namespace posed::sim {
namespace {

/// A box turned by `roll_rad` about map x (the haunches of the arch and what is fixed to them).
void add_rolled(World& w, const Eigen::Vector3d& center_m, const Eigen::Vector3d& half_extent_m,
                double roll_rad, std::uint32_t material) {
  Box b;
  b.center_m = center_m;
  b.half_extent_m = half_extent_m;
  b.R_map_box = Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()).toRotationMatrix();
  b.material = material;
  w.boxes.push_back(b);
}

/// The cross-section, the same all along x: vertical walls at y = ±half_width up to wall_height,
/// 45° haunches rising `haunch` [m] inwards and upwards, a flat crown between them.
struct Profile {
  double half_width = 0, wall_height = 0, haunch = 0.8;
  double crown() const { return wall_height + haunch; }
  double crown_half_width() const { return half_width - haunch; }
};

constexpr double kShell = 0.3;  // shell thickness [m]

/// A machine niche: [x0, x1] on `side` (±1), `depth` [m] into the rock behind the wall.
struct Niche {
  double x0 = 0, x1 = 0, side = 1, depth = 1.5;
};

/// One side's wall from -L to L, with an opening at each of its niches, and the niches' shells.
void add_wall(World& w, const Profile& p, double L, double side, const std::vector<Niche>& niches,
              std::uint32_t shotcrete) {
  const double y_in = side * p.half_width, y_out = side * (p.half_width + kShell);
  double x = -L;
  for (const Niche& n : niches) {
    if (n.side != side) continue;
    w.add_aabb({x, std::min(y_in, y_out), 0}, {n.x0, std::max(y_in, y_out), p.wall_height},
               shotcrete);
    // The niche: back wall, side walls, roof.
    const double y_back = side * (p.half_width + n.depth);
    const double y_back_out = side * (p.half_width + n.depth + kShell);
    w.add_aabb({n.x0, std::min(y_back, y_back_out), 0},
               {n.x1, std::max(y_back, y_back_out), p.wall_height}, shotcrete);
    for (const double xs : {n.x0 - kShell, n.x1})
      w.add_aabb({xs, std::min(y_in, y_back), 0},
                 {xs + kShell, std::max(y_in, y_back), p.wall_height}, shotcrete);
    w.add_aabb({n.x0, std::min(y_in, y_back_out), p.wall_height},
               {n.x1, std::max(y_in, y_back_out), p.wall_height + kShell}, shotcrete);
    x = n.x1;
  }
  w.add_aabb({x, std::min(y_in, y_out), 0}, {L, std::max(y_in, y_out), p.wall_height}, shotcrete);
}

/// Haunches, crown and end walls.
void add_roof_and_ends(World& w, const Profile& p, double L, std::uint32_t shotcrete) {
  const double h = p.haunch;
  const double half_len = 0.5 * h * std::numbers::sqrt2 + 0.15;  // overlaps wall and crown
  for (const double side : {-1.0, 1.0}) {
    // Outward normal (into the rock) (0, side, 1)/√2; the slab's own z axis after rolling by
    // -side·45° about x.
    const Eigen::Vector3d outward = Eigen::Vector3d(0, side, 1).normalized();
    const Eigen::Vector3d mid(0, side * (p.half_width - 0.5 * h), p.wall_height + 0.5 * h);
    add_rolled(w, mid + 0.5 * kShell * outward, {L, half_len, 0.5 * kShell},
               -side * std::numbers::pi / 4, shotcrete);
  }
  const double cw = p.crown_half_width() + 0.2;
  w.add_aabb({-L, -cw, p.crown()}, {L, cw, p.crown() + kShell}, shotcrete);
  for (const double side : {-1.0, 1.0}) {
    const double x = side * L;
    w.add_aabb({std::min(x, x + side * kShell), -p.half_width, 0},
               {std::max(x, x + side * kShell), p.half_width, p.crown()}, shotcrete);
  }
}

/// A rock-bolt plate (0.15 m square, 1.5 cm proud) at `x` on each wall at `z_wall`, on each
/// haunch and twice across the crown; none on a wall where a niche opens.
void add_bolt_ring(World& w, const Profile& p, double x, double z_wall, ScenarioRng& rng,
                   const std::vector<Niche>& niches, std::uint32_t plate) {
  constexpr double kHalf = 0.075, kProud = 0.015;
  for (const double side : {-1.0, 1.0}) {
    const double xw = x + uniform(rng, -0.1, 0.1);
    const bool in_niche = std::any_of(niches.begin(), niches.end(), [&](const Niche& n) {
      return n.side == side && xw > n.x0 - 0.5 && xw < n.x1 + 0.5;
    });
    if (!in_niche) {
      const double y = side * (p.half_width - 0.5 * kProud);
      w.add_aabb({xw - kHalf, y - 0.5 * kProud, z_wall - kHalf},
                 {xw + kHalf, y + 0.5 * kProud, z_wall + kHalf}, plate);
    }
    const Eigen::Vector3d inward = -Eigen::Vector3d(0, side, 1).normalized();
    const Eigen::Vector3d on(x + uniform(rng, -0.1, 0.1), side * (p.half_width - 0.5 * p.haunch),
                             p.wall_height + 0.5 * p.haunch);
    add_rolled(w, on + 0.5 * kProud * inward, {kHalf, kHalf, 0.5 * kProud},
               -side * std::numbers::pi / 4, plate);
    const double xc = x + uniform(rng, -0.1, 0.1), yc = side * 0.5 * p.crown_half_width();
    w.add_aabb({xc - kHalf, yc - kHalf, p.crown() - kProud}, {xc + kHalf, yc + kHalf, p.crown()},
               plate);
  }
}

}  // namespace

RoadwayShape build_roadway(World& w, ScenarioRng& rng, const RoadwayLayout& layout) {
  const double air = w.air_temperature_c;
  const double L = layout.half_length_m;
  const double D = std::min(layout.detail_half_length_m, L - 0.5);
  Profile p;
  p.half_width = uniform(rng, 2.1, 2.5);
  p.wall_height = uniform(rng, 2.3, 2.7);
  const double pipes_side = rng() % 2 == 0 ? -1.0 : 1.0, cables_side = -pipes_side;

  // Sprayed concrete: grey, blotchy at 7 and 35 cm with real contrast; a little warmer than the
  // ventilation air (the rock behind it is warmer still).
  const auto shotcrete =
      w.add_material({25, 0.35, kTextureNoise, 0.6, air + 1.0, 0, {0.85, 0.88, 0.9}});
  const auto plate = w.add_material({50, 0.5, kTexturePlain, 0, air + 2.5, 0, {0.7, 0.72, 0.75}});
  // Compressed air, warm from the compressor: a bare, blue-painted pipe; its galvanised
  // couplings read colder (low emissivity: they reflect the cooler walls), the strap hangers
  // between pipe and air.
  const double air_pipe_c = air + uniform(rng, 6, 9);
  const auto air_pipe = w.add_material({35, 0.3, kTexturePlain, 0, air_pipe_c, 0, {0.8, 0.5, 0.2}});
  const auto coupling =
      w.add_material({60, 0.6, kTexturePlain, 0, air_pipe_c - 5, 0, {0.9, 0.9, 0.9}});
  const auto strap =
      w.add_material({50, 0.5, kTexturePlain, 0, air_pipe_c - 2, 0, {0.8, 0.8, 0.8}});
  // Hot water: insulated, aluminium cladding near air temperature; the insulation is cut back
  // around each flanged joint, leaving 0.3 m of bare pipe and flange at the water's temperature.
  const auto cladding =
      w.add_material({55, 0.6, kTextureNoise, 0.15, air + 2.5, 0, {0.9, 0.9, 0.9}});
  const auto flange =
      w.add_material({40, 0.3, kTexturePlain, 0, uniform(rng, 38, 45), 0, {0.5, 0.5, 0.6}});
  // Cable trays: loaded power cables run warm, communication cables near air temperature; the
  // galvanised hangers across them stay cool.
  const auto power =
      w.add_material({8, 0.08, kTextureNoise, 0.3, air + uniform(rng, 5, 8), 0, {0.9, 0.9, 0.9}});
  const auto comms = w.add_material({8, 0.12, kTextureNoise, 0.3, air + 1, 0, {0.3, 0.6, 0.9}});
  const auto hanger = w.add_material({60, 0.55, kTexturePlain, 0, air + 0.5, 0, {0.8, 0.8, 0.8}});
  const auto junction =
      w.add_material({30, 0.45, kTexturePlain, 0, air + uniform(rng, 8, 12), 0, {0.2, 0.7, 0.9}});
  const auto transformer =
      w.add_material({35, 0.4, kTextureStripes, 0.5, uniform(rng, 50, 60), 0, {0.3, 0.6, 0.4}});
  const auto pump =
      w.add_material({35, 0.4, kTexturePlain, 0, uniform(rng, 40, 48), 0, {0.2, 0.3, 0.8}});
  const auto lamp = w.add_material({70, 0.9, kTexturePlain, 0, 40, 2.0, {0.7, 0.9, 1}});

  // Machine niches at long intervals, on either side.
  std::vector<Niche> niches;
  for (double x = -L + uniform(rng, 30, 150); x < L - 30; x += uniform(rng, 150, 250)) {
    const double len = uniform(rng, 3.0, 4.0);
    niches.push_back({x, x + len, rng() % 2 == 0 ? -1.0 : 1.0, 1.5});
  }
  for (const double side : {-1.0, 1.0}) add_wall(w, p, L, side, niches, shotcrete);
  add_roof_and_ends(w, p, L, shotcrete);
  for (const Niche& n : niches) {
    const double cx = 0.5 * (n.x0 + n.x1);
    const double y_back = n.side * (p.half_width + n.depth);
    if (rng() % 5 < 3) {  // a transformer, its fins as stripes
      const double hx = 0.5 * (n.x1 - n.x0) - 0.4, hy = 0.5, hz = 0.8;
      w.add_aabb({cx - hx, std::min(y_back, y_back - n.side * 2 * hy), 0},
                 {cx + hx, std::max(y_back, y_back - n.side * 2 * hy), 2 * hz}, transformer);
    } else {  // a pump
      w.add_aabb({cx - 0.6, std::min(y_back, y_back - n.side * 0.6), 0},
                 {cx + 0.6, std::max(y_back, y_back - n.side * 0.6), 0.8}, pump);
    }
  }

  // Services the whole length: pipes on one wall, cable trays on the other, flush against it.
  const auto along = [&](double side, double depth_m, double z_m, double half_height_m,
                         std::uint32_t material) {
    const double y0 = side * p.half_width, y1 = side * (p.half_width - depth_m);
    w.add_aabb({-L, std::min(y0, y1), z_m - half_height_m},
               {L, std::max(y0, y1), z_m + half_height_m}, material);
  };
  // Rings around a pipe or a tray at x, `proud_m` beyond its faces (into the wall is hidden).
  const auto ring = [&](double x, double half_len_m, double side, double depth_m, double z_m,
                        double half_height_m, double proud_m, std::uint32_t material) {
    const double y0 = side * (p.half_width + proud_m),
                 y1 = side * (p.half_width - depth_m - proud_m);
    w.add_aabb({x - half_len_m, std::min(y0, y1), z_m - half_height_m - proud_m},
               {x + half_len_m, std::max(y0, y1), z_m + half_height_m + proud_m}, material);
  };
  const double z_air = uniform(rng, 1.6, 1.9), z_hot = uniform(rng, 0.6, 0.9);
  along(pipes_side, 0.16, z_air, 0.08, air_pipe);
  along(pipes_side, 0.24, z_hot, 0.12, cladding);
  const double z_power = uniform(rng, 1.9, 2.1), z_comms = z_power - 0.35;
  along(cables_side, 0.25, z_power, 0.04, power);
  along(cables_side, 0.25, z_comms, 0.04, comms);
  // Pipe sections are 6 m long: a coupling (air) or a flange pair (hot water) at each joint,
  // a strap hanger halfway; the trays hang every 1.5 m.
  for (double x = -D + uniform(rng, 0, 6); x < D; x += 6.0) {
    ring(x, 0.06, pipes_side, 0.16, z_air, 0.08, 0.02, coupling);
    ring(x + 3.0, 0.03, pipes_side, 0.16, z_air, 0.08, 0.01, strap);
  }
  for (double x = -D + uniform(rng, 0, 6); x < D; x += 6.0)
    ring(x, 0.15, pipes_side, 0.24, z_hot, 0.12, 0.005, flange);
  for (double x = -D + uniform(rng, 0, 1.5); x < D; x += 1.5) {
    ring(x, 0.04, cables_side, 0.25, z_power, 0.04, 0.015, hanger);
    ring(x, 0.04, cables_side, 0.25, z_comms, 0.04, 0.015, hanger);
  }
  // Junction boxes under the trays, 12 cm deep: the only relief on the walls between niches.
  for (double x = -L + uniform(rng, 10, 60); x < L; x += uniform(rng, 30, 60)) {
    const bool in_niche = std::any_of(niches.begin(), niches.end(), [&](const Niche& n) {
      return n.side == cables_side && x > n.x0 - 0.5 && x < n.x1 + 0.5;
    });
    const double z = uniform(rng, 0.7, 0.85);
    if (in_niche) continue;
    const double y0 = cables_side * p.half_width, y1 = cables_side * (p.half_width - 0.12);
    w.add_aabb({x - 0.2, std::min(y0, y1), z - 0.22}, {x + 0.2, std::max(y0, y1), z + 0.22},
               junction);
  }
  // Rock bolts on a 1.0-1.4 m ring spacing, their plates on walls, haunches and crown.
  for (double x = -D + uniform(rng, 0, 1.4); x < D; x += uniform(rng, 1.0, 1.4))
    add_bolt_ring(w, p, x, 1.3 + uniform(rng, -0.08, 0.08), rng, niches, plate);
  // Roof lamps, flush with the crown (2 cm).
  for (double x = -L + uniform(rng, 0, layout.lamp_spacing_max_m); x < L;
       x += uniform(rng, layout.lamp_spacing_min_m, layout.lamp_spacing_max_m)) {
    w.add_aabb({x - 0.3, -0.15, p.crown() - 0.02}, {x + 0.3, 0.15, p.crown()}, lamp);
    w.lights.push_back({{x, 0, p.crown() - 0.1}, layout.lamp_intensity});
  }
  return {p.half_width, p.half_width - 0.265};  // the trays and their hangers
}

}  // namespace posed::sim
