#include "tools/sim/scenarios.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include "tools/sim/campus.hpp"
#include "tools/sim/path_layout.hpp"
#include "tools/sim/roadway.hpp"
#include "tools/sim/scenario_random.hpp"

namespace posed::sim {
namespace {

constexpr double kPi = std::numbers::pi;
using Rng = ScenarioRng;

/// Holds and quintic ramps between random cruise speeds, with stops, after a static start.
SpeedProfile make_speed(Rng& rng, double duration_s, double static_s, double v_min, double v_max,
                        double accel_mps2, double stop_probability) {
  std::vector<SpeedRamp> ramps;
  double t = static_s, speed = 0;
  while (t < duration_s + 5.0) {
    double target = uniform(rng, v_min, v_max);
    if (speed > 0 && uniform(rng, 0, 1) < stop_probability) target = 0;
    // Peak acceleration of a quintic ramp is 1.875 Δv / T.
    const double T = std::max(1.0, 1.875 * std::abs(target - speed) / accel_mps2);
    ramps.push_back({t, T, speed, target, 0});
    t += T + (target == 0 ? uniform(rng, 1.0, 3.0) : uniform(rng, 3.0, 10.0));
    speed = target;
  }
  return SpeedProfile(std::move(ramps));
}

std::vector<Wobble> make_wobble(Rng& rng, double amplitude) {
  std::vector<Wobble> w;
  for (int k = 0; k < 3; ++k) {
    w.push_back({amplitude * uniform(rng, 0.5, 1.0) / std::sqrt(3.0),
                 2 * kPi * uniform(rng, 0.7, 3.0), uniform(rng, 0, 2 * kPi)});
  }
  return w;
}

TrajectoryConfig make_bumps(Rng& rng, double z_m, double angle_rad, double gravity) {
  TrajectoryConfig c;
  c.gravity_mps2 = gravity;
  c.z_wobble = make_wobble(rng, z_m);
  c.roll_wobble = make_wobble(rng, angle_rad);
  c.pitch_wobble = make_wobble(rng, angle_rad);
  return c;
}

/// A closed loop around the origin: `n` waypoints at radius r·(1 + jitter) per axis scale.
std::vector<Eigen::Vector2d> loop_waypoints(Rng& rng, int n, double rx, double ry, double jitter) {
  std::vector<Eigen::Vector2d> pts;
  const double phase = uniform(rng, 0, 2 * kPi);
  for (int i = 0; i < n; ++i) {
    const double a = phase + 2 * kPi * i / n;
    const double r = 1.0 + uniform(rng, -jitter, jitter);
    pts.emplace_back(rx * r * std::cos(a), ry * r * std::sin(a));
  }
  return pts;
}

/// Along x and back: down the right-hand lane (y = -lane) from x = -run to +run, a U-turn of
/// radius `lane`, back the other lane, a U-turn: a long thin loop starting at (-run, -lane).
std::vector<Eigen::Vector2d> out_and_back(double run, double lane) {
  std::vector<Eigen::Vector2d> pts;
  for (double x = -run; x <= run; x += 10) pts.emplace_back(x, -lane);
  for (int k = 1; k < 6; ++k) {
    const double a = -kPi / 2 + kPi * k / 6;
    pts.emplace_back(run + lane * std::cos(a), lane * std::sin(a));
  }
  for (double x = run; x >= -run; x -= 10) pts.emplace_back(x, lane);
  for (int k = 1; k < 6; ++k) {
    const double a = kPi / 2 + kPi * k / 6;
    pts.emplace_back(-run + lane * std::cos(a), lane * std::sin(a));
  }
  return pts;
}

void add_ground(World& w, std::uint32_t material) {
  w.add_aabb({-600, -600, -0.3}, {600, 600, 0}, material);
}

/// A scenario's light and temperatures (World's fields of the same names).
struct Environment {
  double ambient = 0, headlight = 0, sky_radiance = 0;
  double air_temperature_c = 15, sky_temperature_c = -20;
};

/// How a scenario drives: a standing start, then holds and ramps between random speeds with
/// stops, and bumps (at full speed) in height, roll and pitch.
struct DriveStyle {
  double v_min_mps = 0, v_max_mps = 0, accel_mps2 = 0, stop_probability = 0;
  double bump_z_m = 0, bump_angle_rad = 0;
  double static_s = 2.0;
};

/// An empty scenario with its own random stream: the world's environment set, nothing in it.
/// `salt` keeps the scenarios' streams apart for one seed.
Scenario begin_scenario(std::string name, std::uint64_t seed, std::uint64_t salt,
                        const Environment& env, Rng& rng) {
  rng.seed(seed * 0x9E3779B97F4A7C15ull + salt);
  Scenario s;
  s.name = std::move(name);
  s.world.ambient = env.ambient;
  s.world.headlight = env.headlight;
  s.world.sky_radiance = env.sky_radiance;
  s.world.air_temperature_c = env.air_temperature_c;
  s.world.sky_temperature_c = env.sky_temperature_c;
  return s;
}

/// The drive along `path` in `style`, covering `duration_s`. Draws the bumps, then the speeds:
/// the order in which the scenarios' drives have always been drawn for a seed (the arguments of
/// one Trajectory(...) call, which GCC evaluates right to left).
Trajectory drive(Rng& rng, const PeriodicSpline2& path, const DriveStyle& style, double duration_s,
                 double gravity) {
  TrajectoryConfig bumps = make_bumps(rng, style.bump_z_m, style.bump_angle_rad, gravity);
  SpeedProfile speed = make_speed(rng, duration_s, style.static_s, style.v_min_mps, style.v_max_mps,
                                  style.accel_mps2, style.stop_probability);
  return Trajectory(path, std::move(speed), std::move(bumps));
}

/// A drive's own random stream, apart from the world's, for `--drive-seed` (`salt` as
/// begin_scenario's: one per scenario).
Rng drive_stream(std::uint64_t drive_seed, std::uint64_t salt) {
  return Rng(drive_seed * 0x9E3779B97F4A7C15ull + salt);
}

/// Where a drive goes on a road whose centre line is `road`: from a start drawn along the loop
/// outside [avoid_from_u_m, avoid_from_u_m + avoid_length_m] (where the estimators had better
/// not initialise), in a direction drawn at random, at an offset from the centre line within
/// ±max_offset_m that weaves slowly (nobody holds a line to the centimetre). Draws the start,
/// the direction, then the offset and its weave.
PeriodicSpline2 lane_path(Rng& rng, const PeriodicSpline2& road, double max_offset_m,
                          double avoid_from_u_m, double avoid_length_m) {
  const double L = road.length();
  const double u0 = avoid_from_u_m + avoid_length_m + uniform(rng, 0, L - avoid_length_m);
  const double direction = rng() % 2 == 0 ? 1.0 : -1.0;
  const double weave = uniform(rng, 0, 0.25) * max_offset_m;
  const double offset = uniform(rng, -1, 1) * (max_offset_m - weave);
  // A whole number of weaves, each 80-200 m long, per lap: the line closes on itself.
  const double weaves = std::max(1.0, std::round(L / uniform(rng, 80, 200)));
  const double phase = uniform(rng, 0, 2 * kPi);
  // Waypoints every ~4 m: the spline through them follows bends of 17 m radius within
  // millimetres.
  const int n = static_cast<int>(std::ceil(L / 4.0));
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < n; ++i) {
    const double s = L * i / n;  // along the drive [m]
    const PathFrame f = path_frame(road, u0 + direction * s);
    pts.push_back(f.p + (offset + weave * std::sin(2 * kPi * weaves * s / L + phase)) * f.n);
  }
  return PeriodicSpline2(pts);
}

Scenario room(std::uint64_t seed, double duration_s, double g) {
  // No sky indoors: rays that escape see a ceiling-like temperature.
  Rng rng;
  Scenario s = begin_scenario(
      "room", seed, 1,
      {.ambient = 0.6, .sky_radiance = 0.3, .air_temperature_c = 22, .sky_temperature_c = 21}, rng);
  World& w = s.world;
  const auto floor = w.add_material({35, 0.45, kTextureNoise, 0.35, 21, 0, {0.7, 0.8, 0.9}});
  const auto wall = w.add_material({60, 0.75, kTextureNoise, 0.1, 22, 0, {0.9, 0.95, 1.0}});
  const auto poster = w.add_material({45, 0.6, kTextureChecker, 0.8, 22, 0, {1, 1, 1}});
  const auto wood = w.add_material({30, 0.4, kTextureNoise, 0.5, 22, 0, {0.3, 0.5, 0.7}});
  const auto computer = w.add_material({20, 0.15, kTexturePlain, 0, 38, 0, {0.5, 0.5, 0.5}});
  const auto lamp = w.add_material({70, 0.9, kTexturePlain, 0, 45, 3.0, {0.9, 1, 1}});
  add_ground(w, floor);
  const double hx = uniform(rng, 3.5, 5.0), hy = uniform(rng, 2.5, 4.0), h = 2.8;
  w.add_aabb({-hx - 0.2, -hy - 0.2, 0}, {-hx, hy + 0.2, h}, wall);
  w.add_aabb({hx, -hy - 0.2, 0}, {hx + 0.2, hy + 0.2, h}, wall);
  w.add_aabb({-hx, -hy - 0.2, 0}, {hx, -hy, h}, wall);
  w.add_aabb({-hx, hy, 0}, {hx, hy + 0.2, h}, wall);
  w.add_aabb({-hx - 0.2, -hy - 0.2, h}, {hx + 0.2, hy + 0.2, h + 0.2}, wall);  // ceiling
  // Furniture and posters along the walls, clear of the loop in the middle.
  const int pieces = 6 + static_cast<int>(rng() % 5);
  for (int i = 0; i < pieces; ++i) {
    const int side = static_cast<int>(rng() % 4);
    const double along = uniform(rng, -0.8, 0.8);
    const double sx = uniform(rng, 0.4, 1.2), sy = uniform(rng, 0.3, 0.6);
    const double height = uniform(rng, 0.5, 2.0);
    Eigen::Vector3d c;
    double yaw = 0;
    if (side < 2) {
      c = {along * (hx - 1.2), (side == 0 ? -1 : 1) * (hy - sy - 0.05), height / 2};
    } else {
      c = {(side == 2 ? -1 : 1) * (hx - sy - 0.05), along * (hy - 1.2), height / 2};
      yaw = kPi / 2;
    }
    w.add_yawed(c, {sx, sy, height / 2}, yaw, i % 3 == 0 ? computer : wood);
    // A poster on the wall behind it.
    Eigen::Vector3d pc = c;
    pc.z() = uniform(rng, 1.4, 2.0);
    if (side < 2)
      pc.y() = (side == 0 ? -1 : 1) * (hy - 0.01);
    else
      pc.x() = (side == 2 ? -1 : 1) * (hx - 0.01);
    w.add_yawed(pc, {uniform(rng, 0.3, 0.6), 0.01, 0.3}, yaw, poster);
  }
  for (double x : {-hx / 2, hx / 2})
    for (double y : {-hy / 2, hy / 2}) {
      w.add_aabb({x - 0.3, y - 0.3, h - 0.05}, {x + 0.3, y + 0.3, h}, lamp);
      w.lights.push_back({{x, y, h - 0.1}, 1.5});
    }
  PeriodicSpline2 path(loop_waypoints(rng, 8, hx - 1.7, hy - 1.5, 0.12));
  s.trajectory = drive(rng, path,
                       {.v_min_mps = 0.3,
                        .v_max_mps = 0.8,
                        .accel_mps2 = 0.4,
                        .stop_probability = 0.15,
                        .bump_z_m = 0.002,
                        .bump_angle_rad = 0.003},
                       duration_s, g);
  return s;
}

Scenario corridor(std::uint64_t seed, double duration_s, double g) {
  Rng rng;
  Scenario s = begin_scenario(
      "corridor", seed, 2,
      {.ambient = 0.02, .headlight = 0.6, .air_temperature_c = 20, .sky_temperature_c = 20}, rng);
  World& w = s.world;
  const auto floor = w.add_material({30, 0.35, kTextureNoise, 0.08, 20, 0, {0.8, 0.85, 0.9}});
  const auto wall = w.add_material({55, 0.7, kTexturePlain, 0, 20.5, 0, {0.85, 0.95, 1.0}});
  const auto end_wall = w.add_material({5, 0.1, kTexturePlain, 0, 20, 0, {1, 1, 1}});
  const auto lamp = w.add_material({70, 0.9, kTexturePlain, 0, 35, 2.0, {0.9, 1, 1}});
  const auto radiator = w.add_material({40, 0.6, kTextureStripes, 0.3, 45, 0, {1, 1, 1}});
  add_ground(w, floor);
  const double half_len = 150, half_w = uniform(rng, 1.4, 1.8), h = 2.8;
  // Walls and ceiling flush along the axis: nothing on them varies with x for the lidar.
  w.add_aabb({-half_len, -half_w - 0.3, 0}, {half_len, -half_w, h}, wall);
  w.add_aabb({-half_len, half_w, 0}, {half_len, half_w + 0.3, h}, wall);
  w.add_aabb({-half_len, -half_w - 0.3, h}, {half_len, half_w + 0.3, h + 0.3}, wall);
  w.add_aabb({-half_len - 0.3, -half_w, 0}, {-half_len, half_w, h}, end_wall);
  w.add_aabb({half_len, -half_w, 0}, {half_len + 0.3, half_w, h}, end_wall);
  for (double x = -half_len + uniform(rng, 2, 10); x < half_len; x += uniform(rng, 8, 14)) {
    w.add_aabb({x - 0.3, -0.15, h - 0.02}, {x + 0.3, 0.15, h}, lamp);  // flush ceiling panels
    w.lights.push_back({{x, 0, h - 0.1}, 0.25});
  }
  // Radiators: thin, flush (2 cm) so the lidar barely sees them; the thermal camera does.
  for (double x = -half_len + uniform(rng, 5, 20); x < half_len; x += uniform(rng, 15, 30)) {
    const double side = (rng() % 2 == 0) ? -1 : 1;
    const double y0 = side * half_w;
    w.add_aabb({x - 0.6, std::min(y0, y0 - side * 0.02), 0.2},
               {x + 0.6, std::max(y0, y0 - side * 0.02), 0.8}, radiator);
  }
  const double run = uniform(rng, 25, 40), lane = half_w - 0.75;
  s.trajectory = drive(rng, PeriodicSpline2(out_and_back(run, lane)),
                       {.v_min_mps = 0.6,
                        .v_max_mps = 1.4,
                        .accel_mps2 = 0.4,
                        .stop_probability = 0.1,
                        .bump_z_m = 0.003,
                        .bump_angle_rad = 0.004},
                       duration_s, g);
  return s;
}

Scenario mine(std::uint64_t seed, double duration_s, double g) {
  Rng rng;
  Scenario s = begin_scenario(
      "mine", seed, 3,
      {.ambient = 0.003, .headlight = 1.0, .air_temperature_c = 17, .sky_temperature_c = 17}, rng);
  World& w = s.world;
  const auto ground = w.add_material({15, 0.2, kTextureNoise, 0.3, 16, 0, {0.6, 0.65, 0.7}});
  const auto rock = w.add_material({22, 0.25, kTextureNoise, 0.25, 17, 0, {0.6, 0.7, 0.75}});
  const auto machine = w.add_material({35, 0.35, kTextureStripes, 0.5, 55, 0, {0.2, 0.6, 0.9}});
  const auto lamp = w.add_material({70, 0.9, kTexturePlain, 0, 60, 2.5, {0.7, 0.9, 1}});
  add_ground(w, ground);
  const double R = uniform(rng, 25, 40);
  PeriodicSpline2 path(loop_waypoints(rng, 10, R, R * uniform(rng, 0.6, 1.0), 0.2));
  const auto samples = sample_path(path, 0.5);
  const double half_w = uniform(rng, 1.8, 2.3), h = 3.2;
  for (double u = 0; u < path.length(); u += 1.0) {
    const PathFrame f = path_frame(path, u);
    for (double side : {-1.0, 1.0}) {
      const double thick = uniform(rng, 0.5, 1.2);
      const double lateral = half_w + uniform(rng, 0.0, 0.45) + thick;
      const double yaw = f.yaw + uniform(rng, -0.25, 0.25);
      const Eigen::Vector2d c = f.p + side * lateral * f.n;
      const double hh = h + uniform(rng, -0.3, 0.3);
      if (!clear_of_path(samples, c, 0.7, thick, yaw, half_w - 0.2)) continue;
      w.add_yawed({c.x(), c.y(), hh / 2}, {0.7, thick, hh / 2}, yaw, rock);
    }
    // Roof: a slab across the tunnel, at a rough height.
    const double roof = h + uniform(rng, -0.25, 0.2);
    w.add_yawed({f.p.x(), f.p.y(), roof + 0.3}, {0.65, half_w + 1.5, 0.3},
                f.yaw + uniform(rng, -0.1, 0.1), rock);
    if (rng() % 40 == 0) {  // a warm machine in a niche
      const double side = (rng() % 2 == 0) ? -1 : 1;
      const Eigen::Vector2d c = f.p + side * (half_w - 0.1) * f.n;
      if (clear_of_path(samples, c, 0.8, 0.4, f.yaw, 1.0))
        w.add_yawed({c.x(), c.y(), 0.6}, {0.8, 0.4, 0.6}, f.yaw, machine);
    }
    if (static_cast<int>(u) % 20 == 0) {
      w.add_yawed({f.p.x(), f.p.y(), roof - 0.05}, {0.15, 0.15, 0.05}, f.yaw, lamp);
      w.lights.push_back({{f.p.x(), f.p.y(), roof - 0.2}, 0.3});
    }
  }
  s.trajectory = drive(rng, path,
                       {.v_min_mps = 0.5,
                        .v_max_mps = 1.5,
                        .accel_mps2 = 0.5,
                        .stop_probability = 0.15,
                        .bump_z_m = 0.02,
                        .bump_angle_rad = 0.02},
                       duration_s, g);
  return s;
}

Scenario street_night(std::uint64_t seed, std::optional<std::uint64_t> drive_seed,
                      double duration_s, double g) {
  Rng rng;
  Scenario s = begin_scenario("street_night", seed, 4,
                              {.ambient = 0.01,
                               .headlight = 0.8,
                               .sky_radiance = 0.02,
                               .air_temperature_c = 12,
                               .sky_temperature_c = -30},
                              rng);
  World& w = s.world;
  const auto asphalt = w.add_material({12, 0.12, kTextureNoise, 0.3, 16, 0, {0.8, 0.8, 0.8}});
  const auto brick = w.add_material({30, 0.35, kTextureBricks, 0.6, 13, 0, {0.4, 0.5, 0.75}});
  const auto concrete = w.add_material({40, 0.5, kTextureNoise, 0.3, 14, 0, {0.85, 0.85, 0.85}});
  const auto window = w.add_material({8, 0.3, kTextureChecker, 0.5, 15, 0.4, {0.5, 0.8, 1.0}});
  const auto pole = w.add_material({35, 0.3, kTexturePlain, 0, 11, 0, {0.5, 0.5, 0.5}});
  const auto lamp = w.add_material({80, 0.9, kTexturePlain, 0, 70, 4.0, {0.6, 0.85, 1.0}});
  const auto car_cold = w.add_material({25, 0.4, kTexturePlain, 0, 11, 0, {0.2, 0.2, 0.7}});
  const auto car_warm = w.add_material({25, 0.4, kTexturePlain, 0, 42, 0, {0.7, 0.3, 0.2}});
  const auto person = w.add_material({15, 0.3, kTexturePlain, 0, 32, 0, {0.3, 0.4, 0.5}});
  const auto sign = w.add_material({220, 0.8, kTextureStripes, 0.8, 11, 0, {0.1, 0.8, 1.0}});
  add_ground(w, asphalt);
  const double rx = uniform(rng, 45, 70), ry = uniform(rng, 30, 50);
  PeriodicSpline2 path(loop_waypoints(rng, 12, rx, ry, 0.12));
  const auto samples = sample_path(path, 1.0);
  const double road = 4.0;  // half width of the road [m]
  for (double side : {-1.0, 1.0}) {
    // Buildings, with gaps, set back from the kerb.
    for (double u = uniform(rng, 0, 10); u < path.length(); u += uniform(rng, 14, 28)) {
      const PathFrame f = path_frame(path, u);
      const double len = uniform(rng, 5, 11), depth = uniform(rng, 4, 8);
      const double height = uniform(rng, 6, 20);
      const double lateral = road + uniform(rng, 3, 7) + depth;
      const Eigen::Vector2d c = f.p + side * lateral * f.n;
      if (!clear_of_path(samples, c, len, depth, f.yaw, road + 2.5)) continue;
      w.add_yawed({c.x(), c.y(), height / 2}, {len, depth, height / 2}, f.yaw,
                  rng() % 2 == 0 ? brick : concrete);
      // Lit windows on the street side.
      const Eigen::Vector2d wc = f.p + side * (lateral - depth - 0.02) * f.n;
      for (double z = 2.5; z < height - 1; z += 3.2)
        if (rng() % 3 == 0) w.add_yawed({wc.x(), wc.y(), z}, {len * 0.7, 0.03, 0.6}, f.yaw, window);
    }
    // Street lights.
    for (double u = uniform(rng, 0, 20); u < path.length(); u += uniform(rng, 20, 32)) {
      const PathFrame f = path_frame(path, u);
      const Eigen::Vector2d c = f.p + side * (road + 0.8) * f.n;
      if (!clear_of_path(samples, c, 0.1, 0.1, 0, road)) continue;
      w.add_aabb({c.x() - 0.08, c.y() - 0.08, 0}, {c.x() + 0.08, c.y() + 0.08, 6.0}, pole);
      const Eigen::Vector2d head = f.p + side * (road - 0.2) * f.n;
      w.add_yawed({head.x(), head.y(), 6.0}, {0.3, 0.6, 0.08}, f.yaw, lamp);
      w.lights.push_back({{head.x(), head.y(), 5.8}, 25.0});
      if (rng() % 3 == 0) w.add_yawed({c.x(), c.y(), 2.5}, {0.02, 0.3, 0.3}, f.yaw + kPi / 2, sign);
    }
    // Parked cars along the kerb, some with warm engines; pedestrians on the pavement.
    for (double u = uniform(rng, 0, 15); u < path.length(); u += uniform(rng, 8, 30)) {
      const PathFrame f = path_frame(path, u);
      const Eigen::Vector2d c = f.p + side * (road - 1.0) * f.n;
      if (!clear_of_path(samples, c, 2.3, 0.9, f.yaw, 1.6)) continue;
      w.add_yawed({c.x(), c.y(), 0.75}, {2.3, 0.9, 0.75}, f.yaw,
                  rng() % 3 == 0 ? car_warm : car_cold);
    }
    for (double u = uniform(rng, 0, 15); u < path.length(); u += uniform(rng, 15, 40)) {
      const PathFrame f = path_frame(path, u);
      const Eigen::Vector2d c = f.p + side * (road + uniform(rng, 1.2, 2.5)) * f.n;
      if (!clear_of_path(samples, c, 0.25, 0.2, f.yaw, road)) continue;
      w.add_yawed({c.x(), c.y(), 0.85}, {0.25, 0.2, 0.85}, f.yaw, person);
    }
  }
  const DriveStyle style{.v_min_mps = 2.0,
                         .v_max_mps = 6.0,
                         .accel_mps2 = 0.8,
                         .stop_probability = 0.12,
                         .bump_z_m = 0.008,
                         .bump_angle_rad = 0.006};
  if (!drive_seed) {
    // Along the centre line from u = 0, drawn from the world's stream after the world: the drive
    // this scenario has always had for a seed.
    s.trajectory = drive(rng, path, style, duration_s, g);
    return s;
  }
  // Another drive in the same world: within 0.6 m of the centre line, which keeps a metre from
  // the parked cars (the nearest things, 1.6 m from it on the inside of bends).
  Rng drive_rng = drive_stream(*drive_seed, 0x104);
  s.trajectory = drive(drive_rng, lane_path(drive_rng, path, 0.6, 0, 0), style, duration_s, g);
  return s;
}

/// A coal-mine roadway (roadway.hpp) long enough that the lidar never sees its ends: the
/// drive's straight legs run from x = -run to +run, the shell 215 m beyond them (the VLP-32C
/// reaches 200 m), with its small things to 60 m beyond them, on a dusty floor, and the drive
/// through it. Draws the run, the roadway, then the drive.
void roadway_drive(Scenario& s, Rng& rng, RoadwayLayout layout, double duration_s, double g) {
  World& w = s.world;
  add_ground(w, w.add_material(
                    {12, 0.15, kTextureNoise, 0.4, w.air_temperature_c + 0.5, 0, {0.8, 0.8, 0.8}}));
  const double run = uniform(rng, 110, 140);
  layout.half_length_m = run + 215;
  layout.detail_half_length_m = run + 60;
  const RoadwayShape shape = build_roadway(s.world, rng, layout);
  s.trajectory = drive(rng, PeriodicSpline2(out_and_back(run, shape.clear_half_width_m - 0.75)),
                       {.v_min_mps = 0.5,
                        .v_max_mps = 1.5,
                        .accel_mps2 = 0.5,
                        .stop_probability = 0.15,
                        .bump_z_m = 0.02,
                        .bump_angle_rad = 0.02},
                       duration_s, g);
}

Scenario tunnel(std::uint64_t seed, double duration_s, double g) {
  // A deep mine's ventilation air is warm; rays beyond the cameras' range see more roadway.
  Rng rng;
  Scenario s = begin_scenario(
      "tunnel", seed, 5,
      {.ambient = 0.003, .headlight = 1.0, .air_temperature_c = 24, .sky_temperature_c = 25}, rng);
  // A rare dim lamp: the headlight does nearly all the lighting.
  roadway_drive(s, rng,
                {.lamp_spacing_min_m = 60, .lamp_spacing_max_m = 120, .lamp_intensity = 0.3},
                duration_s, g);
  return s;
}

Scenario smoke(std::uint64_t seed, double duration_s, double g) {
  Rng rng;
  Scenario s = begin_scenario(
      "smoke", seed, 6,
      {.ambient = 0.01, .headlight = 1.0, .air_temperature_c = 24, .sky_temperature_c = 25}, rng);
  // A lit roadway: lamps every 12-20 m.
  roadway_drive(s, rng, {.lamp_spacing_min_m = 12, .lamp_spacing_max_m = 20, .lamp_intensity = 1.0},
                duration_s, g);
  // The smoke comes at 30-45 % of the run, thickens over a few seconds, stays dense for 20-30 %
  // of the run and clears more slowly (ramps shortened for runs under a minute).
  SmokeSchedule& smoke = s.world.smoke;
  const double ramp = std::min(1.0, duration_s / 60.0);
  smoke.start_s = uniform(rng, 0.30, 0.45) * duration_s;
  smoke.dense_from_s = smoke.start_s + uniform(rng, 3, 6) * ramp;
  smoke.dense_to_s = smoke.dense_from_s + uniform(rng, 0.20, 0.30) * duration_s;
  smoke.clear_s = smoke.dense_to_s + uniform(rng, 4, 8) * ramp;
  smoke.dense_extinction_per_m = uniform(rng, 2.5, 4.0);
  smoke.albedo = uniform(rng, 0.2, 0.3);
  return s;
}

/// A campus by day (campus.hpp): a figure-of-eight ring road, 750-860 m around, with an open
/// stretch by a sports field. The drive comes from its own stream, seeded by the drive seed
/// (the world's seed unless another is given): anywhere on the road but near the open stretch,
/// in either direction, within 2 m of the centre line (1.5 m from the kerbs), 2.8-4 m/s with a
/// few stops: 600 s go round the loop twice or more.
Scenario campus(std::uint64_t seed, std::optional<std::uint64_t> drive_seed, double duration_s,
                double g) {
  Rng rng;
  Scenario s = begin_scenario(
      "campus", seed, 7,
      {.ambient = 1.0, .sky_radiance = 0.9, .air_temperature_c = 18, .sky_temperature_c = -8}, rng);
  // Sunlit paving, warmer than the air.
  add_ground(s.world,
             s.world.add_material({20, 0.3, kTextureNoise, 0.35, 26, 0, {0.75, 0.78, 0.8}}));
  const CampusShape shape = build_campus(s.world, rng);
  Rng drive_rng = drive_stream(drive_seed.value_or(seed), 0x107);
  // The start keeps 100 m from the open stretch: the estimators initialise, and drive their
  // first seconds, where the lidar sees something.
  const PeriodicSpline2 lane = lane_path(drive_rng, shape.road, shape.road_half_width_m - 1.5,
                                         shape.open_from_u_m - 100, shape.open_length_m + 200);
  s.trajectory = drive(drive_rng, lane,
                       {.v_min_mps = 2.8,
                        .v_max_mps = 4.0,
                        .accel_mps2 = 0.8,
                        .stop_probability = 0.08,
                        .bump_z_m = 0.006,
                        .bump_angle_rad = 0.005},
                       duration_s, g);
  return s;
}

constexpr std::array<std::string_view, 7> kNames = {"street_night", "corridor", "mine",  "room",
                                                    "tunnel",       "smoke",    "campus"};

}  // namespace

std::span<const std::string_view> scenario_names() { return kNames; }

std::optional<Scenario> make_scenario(std::string_view name, std::uint64_t seed, double duration_s,
                                      double gravity_mps2, std::string& error) {
  return make_scenario(name, seed, std::nullopt, duration_s, gravity_mps2, error);
}

std::optional<Scenario> make_scenario(std::string_view name, std::uint64_t seed,
                                      std::optional<std::uint64_t> drive_seed, double duration_s,
                                      double gravity_mps2, std::string& error) {
  if (name == "street_night") {
    return street_night(seed, drive_seed, duration_s, gravity_mps2);
  }
  if (name == "campus") {
    return campus(seed, drive_seed, duration_s, gravity_mps2);
  }
  if (drive_seed && std::find(kNames.begin(), kNames.end(), name) != kNames.end()) {
    // Their worlds are built around the one drive (a room's furniture around its loop, a
    // tunnel's walls around its lane): there is nowhere else to drive.
    error = "scenario '" + std::string(name) +
            "' has one drive; a drive seed needs a road to drive elsewhere on (campus, "
            "street_night)";
    return std::nullopt;
  }
  if (name == "room") return room(seed, duration_s, gravity_mps2);
  if (name == "corridor") return corridor(seed, duration_s, gravity_mps2);
  if (name == "mine") return mine(seed, duration_s, gravity_mps2);
  if (name == "tunnel") return tunnel(seed, duration_s, gravity_mps2);
  if (name == "smoke") return smoke(seed, duration_s, gravity_mps2);
  error = "unknown scenario '" + std::string(name) + "' (";
  for (std::string_view n : kNames) error += std::string(n) + (n == kNames.back() ? ")" : ", ");
  return std::nullopt;
}

}  // namespace posed::sim
