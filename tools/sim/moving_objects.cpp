#include "tools/sim/moving_objects.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace posed::sim {

namespace {

constexpr double kPersonHalf[3] = {0.15, 0.25, 0.875};  // along, across, up [m]
constexpr double kVehicleHalf[3] = {2.2, 0.9, 0.75};    // [m]
constexpr double kPeoplePer100m = 10.0;
constexpr double kVehiclesPer100m = 4.0;

}  // namespace

MovingObjects::MovingObjects(World& world, const Trajectory& trajectory, bool vehicles,
                             std::uint64_t seed)
    : world_(world), trajectory_(trajectory) {
  std::mt19937_64 rng(seed);
  auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  const double loop_m = trajectory.path().length();
  // Clothes: dark to light, slightly textured; vehicle bodies: painted, retro-reflective plates
  // left out. Warm: people at 30 °C, running vehicles at 35 °C.
  std::vector<std::uint32_t> clothes, paint;
  for (int k = 0; k < 4; ++k) {
    clothes.push_back(world.add_material({25 + 10.0 * k, 0.15 + 0.15 * k, kTextureNoise, 0.3, 30, 0,
                                          Eigen::Vector3d(u(0.5, 1), u(0.5, 1), u(0.5, 1))}));
  }
  for (int k = 0; k < 3; ++k) {
    paint.push_back(world.add_material({50 + 10.0 * k, 0.2 + 0.25 * k, kTexturePlain, 0, 35, 0,
                                        Eigen::Vector3d(u(0.3, 1), u(0.3, 1), u(0.3, 1))}));
  }
  first_box_ = world.boxes.size();
  // n objects of one kind, each somewhere on the loop, with the robot or against it, `lateral_m`
  // to its left (or, `either_side`, to its left or right).
  const auto add = [&](std::size_t n, double min_speed_mps, double max_speed_mps, double lateral_m,
                       bool either_side, const double(&half_m)[3],
                       const std::vector<std::uint32_t>& materials) {
    for (std::size_t k = 0; k < n; ++k) {
      Object o;
      o.u0_m = u(0, loop_m);
      o.speed_mps = (u(0, 1) < 0.5 ? -1 : 1) * u(min_speed_mps, max_speed_mps);
      o.lateral_m = either_side ? (u(0, 1) < 0.5 ? -1 : 1) * lateral_m : lateral_m;
      objects_.push_back(o);
      world.add_yawed(
          Eigen::Vector3d::Zero(), Eigen::Vector3d(half_m[0], half_m[1], half_m[2]), 0,
          materials[static_cast<std::size_t>(u(0, static_cast<double>(materials.size()) - 0.001))]);
    }
  };
  add(static_cast<std::size_t>(std::max(2.0, std::round(kPeoplePer100m * loop_m / 100.0))), 0.7,
      1.6, 0.9, true, kPersonHalf, clothes);
  people_ = objects_.size();
  if (vehicles) {
    // In the next lane, left of the robot's.
    add(static_cast<std::size_t>(std::max(1.0, std::round(kVehiclesPer100m * loop_m / 100.0))), 3,
        9, 3.2, false, kVehicleHalf, paint);
  }
  place(Duration::from_ns(0));
}

void MovingObjects::place(Duration t) {
  const double t_s = t.seconds();
  Eigen::Vector2d p, d1, d2, d3;
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    const Object& o = objects_[k];
    trajectory_.path().eval(o.u0_m + o.speed_mps * t_s, p, d1, d2, d3);
    const Eigen::Vector2d tangent = d1.normalized();
    const Eigen::Vector2d left(-tangent.y(), tangent.x());
    const Eigen::Vector2d at = p + o.lateral_m * left;
    Box& b = world_.boxes[first_box_ + k];
    b.center_m = Eigen::Vector3d(at.x(), at.y(), b.half_extent_m.z());  // on the ground
    const double yaw = std::atan2(tangent.y(), tangent.x()) + (o.speed_mps < 0 ? M_PI : 0.0);
    b.R_map_box = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  }
}

std::optional<RayHit> MovingObjects::cast(const Eigen::Vector3d& origin_m,
                                          const Eigen::Vector3d& dir, double t_max_m) const {
  std::optional<RayHit> best;
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    const Box& b = world_.boxes[first_box_ + k];
    // Bounding sphere first: most objects are far from most rays.
    const Eigen::Vector3d c = b.center_m - origin_m;
    const double along = c.dot(dir);
    const double r = b.half_extent_m.norm();
    if (along < -r || along - r > t_max_m || (c - along * dir).squaredNorm() > r * r) continue;
    auto h = intersect_box(b, origin_m, dir, best ? best->t_m : t_max_m);
    if (h && (!best || h->t_m < best->t_m)) {
      h->box = static_cast<std::uint32_t>(first_box_ + k);
      best = h;
    }
  }
  return best;
}

void MovingObjects::overlay(const PixelRays& rays, const Eigen::Isometry3d& T_map_cam,
                            double max_range_m, GBuffer& out) const {
  const Eigen::Matrix3d R = T_map_cam.linear();
  const Eigen::Vector3d o = T_map_cam.translation();
  const int W = rays.width(), H = rays.height();
  for (std::size_t k = 0; k < objects_.size(); ++k) {
    const Box& b = world_.boxes[first_box_ + k];
    const Eigen::Vector3d c_cam = R.transpose() * (b.center_m - o);
    const double dist = c_cam.norm(), r = b.half_extent_m.norm();
    if (dist - r > max_range_m || c_cam.z() < -r) continue;
    // Pixels whose ray passes within the bounding sphere: the cone about the centre's direction.
    const double cos_cone = dist > r ? std::cos(std::asin(r / dist)) : -1.0;
    const Eigen::Vector3d c_dir = c_cam / std::max(dist, 1e-9);
    for (int y = 0; y < H; ++y) {
      for (int x = 0; x < W; ++x) {
        const Eigen::Vector3d& d = rays.dir(x, y);
        if (d.dot(c_dir) < cos_cone) continue;
        const std::size_t i =
            static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
        const double seen = out.box[i] >= 0 ? out.t_m[i] : max_range_m;
        const auto h = intersect_box(b, o, R * d, seen);
        if (!h) continue;
        out.box[i] = static_cast<std::int32_t>(first_box_ + k);
        out.face[i] = h->face;
        out.t_m[i] = static_cast<float>(h->t_m);
        if (out.cells_x > 0) {
          const int cx = std::min(x / kGridStep, out.cells_x - 1);
          const int cy = std::min(y / kGridStep, out.cells_y - 1);
          out.plane_cell[static_cast<std::size_t>(cy * out.cells_x + cx)] = 0;
        }
      }
    }
  }
}

std::string MovingObjects::describe() const {
  char text[64];
  std::snprintf(text, sizeof text, "%zu people, %zu vehicles", people(), vehicles());
  return text;
}

}  // namespace posed::sim
