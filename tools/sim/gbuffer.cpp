#include "tools/sim/gbuffer.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace posed::sim {
namespace {

/// Face plane of a box: n · p = d (map).
struct Plane {
  Eigen::Vector3d n;
  double d;
};
Plane face_plane(const Box& b, std::uint8_t face) {
  const Eigen::Vector3d n = face_normal_map(b, face);
  const int axis = face / 2;
  return {n, n.dot(b.center_m) + b.half_extent_m[axis]};
}

}  // namespace

PixelRays::PixelRays(const CameraIntrinsics& K, int downscale) {
  width_ = K.width / downscale;
  height_ = K.height / downscale;
  pixel_angle_rad_ = downscale / std::sqrt(K.fx * K.fy);
  dirs_.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      // Pixel centre at full resolution, then undistort by fixed-point iteration.
      const double u = (x + 0.5) * downscale - 0.5, v = (y + 0.5) * downscale - 0.5;
      const double xd = (u - K.cx) / K.fx, yd = (v - K.cy) / K.fy;
      double xu = xd, yu = yd;
      const bool distorted = K.k1 != 0 || K.k2 != 0 || K.p1 != 0 || K.p2 != 0;
      for (int it = 0; distorted && it < 20; ++it) {
        const double xu0 = xu, yu0 = yu;
        const double r2 = xu * xu + yu * yu;
        const double radial = 1 + K.k1 * r2 + K.k2 * r2 * r2;
        const double dx = 2 * K.p1 * xu * yu + K.p2 * (r2 + 2 * xu * xu);
        const double dy = K.p1 * (r2 + 2 * yu * yu) + 2 * K.p2 * xu * yu;
        xu = (xd - dx) / radial;
        yu = (yd - dy) / radial;
        if (std::abs(xu - xu0) + std::abs(yu - yu0) < 1e-12) break;  // converged
      }
      dirs_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
            static_cast<std::size_t>(x)] = Eigen::Vector3d(xu, yu, 1.0).normalized();
    }
  }
}

void render_gbuffer(const World& world, const Bvh& bvh, const PixelRays& rays,
                    const Eigen::Isometry3d& T_map_cam, double max_range_m, GBuffer& out) {
  const int W = rays.width(), H = rays.height();
  const auto N = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
  out.width = W;
  out.height = H;
  // Every pixel is written below: no clearing pass over the three buffers.
  out.box.resize(N);
  out.face.resize(N);
  out.t_m.resize(N);
  const Eigen::Matrix3d R = T_map_cam.linear();
  const Eigen::Vector3d o = T_map_cam.translation();
  auto idx = [W](int x, int y) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
  };
  auto set = [&](std::size_t i, std::int32_t box, std::uint8_t face, double t) {
    out.box[i] = box;
    out.face[i] = face;
    out.t_m[i] = static_cast<float>(t);
  };
  // Grid rays (the last row/column always included so every cell has four corners).
  const int gw = grid_points(W), gh = grid_points(H);
  out.cells_x = gw - 1;
  out.cells_y = gh - 1;
  out.plane_cell.resize(static_cast<std::size_t>(out.cells_x * out.cells_y));
  out.grid_box.assign(static_cast<std::size_t>(gw * gh), -1);
  out.grid_face.assign(static_cast<std::size_t>(gw * gh), 0);
  for (int j = 0; j < gh; ++j)
    for (int i = 0; i < gw; ++i) {
      if (auto h =
              bvh.cast(Ray(o, R * rays.dir(grid_pixel(i, W), grid_pixel(j, H))), max_range_m)) {
        out.grid_box[static_cast<std::size_t>(j * gw + i)] = static_cast<std::int32_t>(h->box);
        out.grid_face[static_cast<std::size_t>(j * gw + i)] = h->face;
      }
    }
  for (int j = 0; j + 1 < gh; ++j) {
    for (int i = 0; i + 1 < gw; ++i) {
      std::array<std::int32_t, 4> cb{}, cand{};
      std::array<std::uint8_t, 4> cf{};
      const std::array<std::size_t, 4> gi = {static_cast<std::size_t>(j * gw + i),
                                             static_cast<std::size_t>(j * gw + i + 1),
                                             static_cast<std::size_t>((j + 1) * gw + i),
                                             static_cast<std::size_t>((j + 1) * gw + i + 1)};
      bool same = true;
      int n = 0;
      for (std::size_t k = 0; k < 4; ++k) {
        cb[k] = out.grid_box[gi[k]];
        cf[k] = out.grid_face[gi[k]];
        same = same && cb[k] == cb[0] && cf[k] == cf[0];
        if (cb[k] >= 0 && std::find(cand.begin(), cand.begin() + n, cb[k]) == cand.begin() + n)
          cand[static_cast<std::size_t>(n++)] = cb[k];
      }
      const int x0 = grid_pixel(i, W), y0 = grid_pixel(j, H);
      const int xe = cell_end(i, gw, W), ye = cell_end(j, gh, H);
      out.plane_cell[static_cast<std::size_t>(j * out.cells_x + i)] = same && cb[0] >= 0;
      if (same && cb[0] < 0) {  // all sky
        for (int y = y0; y < ye; ++y)
          for (int x = x0; x < xe; ++x) set(idx(x, y), -1, 0, 0.0);
        continue;
      }
      if (same) {
        // One face: each pixel's ray against that face's plane (in the camera frame).
        const Plane pl = face_plane(world.boxes[static_cast<std::size_t>(cb[0])], cf[0]);
        const double num = pl.d - pl.n.dot(o);
        const Eigen::Vector3d n_cam = R.transpose() * pl.n;
        for (int y = y0; y < ye; ++y)
          for (int x = x0; x < xe; ++x) {
            const double den = n_cam.dot(rays.dir(x, y));
            const double t = den != 0 ? num / den : -1;
            if (t > 0)
              set(idx(x, y), cb[0], cf[0], t);
            else
              set(idx(x, y), -1, 0, 0.0);
          }
        continue;
      }
      // Corners on different faces: each pixel against the boxes its corners saw.
      for (int y = y0; y < ye; ++y)
        for (int x = x0; x < xe; ++x) {
          const Ray ray(o, R * rays.dir(x, y));
          std::optional<RayHit> best;
          for (int k = 0; k < n; ++k) {
            const auto b = static_cast<std::uint32_t>(cand[static_cast<std::size_t>(k)]);
            if (auto h = bvh.hit_box(b, ray, best ? best->t_m : max_range_m)) {
              if (!best || h->t_m < best->t_m) best = h;
            }
          }
          if (best)
            set(idx(x, y), static_cast<std::int32_t>(best->box), best->face, best->t_m);
          else
            set(idx(x, y), -1, 0, 0.0);
        }
    }
  }
}

}  // namespace posed::sim
