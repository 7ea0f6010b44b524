#include "tools/sim/gbuffer.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace posed::sim {
namespace {

constexpr int kGridStep = 4;

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

/// The hit of one pixel among a few candidate boxes.
bool nearest_among(const World& world, const std::array<std::int32_t, 4>& boxes, int n,
                   const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max,
                   std::int32_t& box, std::uint8_t& face, double& t) {
  bool found = false;
  t = t_max;
  for (int i = 0; i < n; ++i) {
    const auto b = static_cast<std::size_t>(boxes[static_cast<std::size_t>(i)]);
    if (auto h = intersect_box(world.boxes[b], o, d, t)) {
      if (!found || h->t_m < t) {
        t = h->t_m;
        box = static_cast<std::int32_t>(b);
        face = h->face;
        found = true;
      }
    }
  }
  return found;
}

}  // namespace

PixelRays::PixelRays(const CameraIntrinsics& K, int downscale) {
  width_ = K.width / downscale;
  height_ = K.height / downscale;
  dirs_.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      // Pixel centre at full resolution, then undistort by fixed-point iteration.
      const double u = (x + 0.5) * downscale - 0.5, v = (y + 0.5) * downscale - 0.5;
      const double xd = (u - K.cx) / K.fx, yd = (v - K.cy) / K.fy;
      double xu = xd, yu = yd;
      for (int it = 0; it < 20; ++it) {
        const double r2 = xu * xu + yu * yu;
        const double radial = 1 + K.k1 * r2 + K.k2 * r2 * r2;
        const double dx = 2 * K.p1 * xu * yu + K.p2 * (r2 + 2 * xu * xu);
        const double dy = K.p1 * (r2 + 2 * yu * yu) + 2 * K.p2 * xu * yu;
        xu = (xd - dx) / radial;
        yu = (yd - dy) / radial;
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
  out.box.assign(N, -1);
  out.face.assign(N, 0);
  out.t_m.assign(N, 0.f);
  const Eigen::Matrix3d R = T_map_cam.linear();
  const Eigen::Vector3d o = T_map_cam.translation();
  auto idx = [W](int x, int y) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
  };
  // Grid rays (the last row/column always included so every cell has four corners).
  const int gw = (W - 1 + kGridStep - 1) / kGridStep + 1,
            gh = (H - 1 + kGridStep - 1) / kGridStep + 1;
  std::vector<std::int32_t> gbox(static_cast<std::size_t>(gw * gh), -1);
  std::vector<std::uint8_t> gface(static_cast<std::size_t>(gw * gh), 0);
  auto gx = [W](int i) { return std::min(i * kGridStep, W - 1); };
  auto gy = [H](int j) { return std::min(j * kGridStep, H - 1); };
  for (int j = 0; j < gh; ++j)
    for (int i = 0; i < gw; ++i) {
      const Eigen::Vector3d d = R * rays.dir(gx(i), gy(j));
      if (auto h = bvh.cast(o, d, max_range_m)) {
        gbox[static_cast<std::size_t>(j * gw + i)] = static_cast<std::int32_t>(h->box);
        gface[static_cast<std::size_t>(j * gw + i)] = h->face;
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
        cb[k] = gbox[gi[k]];
        cf[k] = gface[gi[k]];
        same = same && cb[k] == cb[0] && cf[k] == cf[0];
        if (cb[k] >= 0 && std::find(cand.begin(), cand.begin() + n, cb[k]) == cand.begin() + n)
          cand[static_cast<std::size_t>(n++)] = cb[k];
      }
      const int x0 = gx(i), x1 = gx(i + 1), y0 = gy(j), y1 = gy(j + 1);
      const int xe = (i + 2 == gw) ? x1 + 1 : x1, ye = (j + 2 == gh) ? y1 + 1 : y1;
      if (same && cb[0] < 0) continue;  // all sky
      if (same) {
        const Plane pl = face_plane(world.boxes[static_cast<std::size_t>(cb[0])], cf[0]);
        const double num = pl.d - pl.n.dot(o);
        const Eigen::Vector3d n_cam = R.transpose() * pl.n;
        for (int y = y0; y < ye; ++y)
          for (int x = x0; x < xe; ++x) {
            const double den = n_cam.dot(rays.dir(x, y));
            const double t = den != 0 ? num / den : -1;
            if (t <= 0) continue;
            out.box[idx(x, y)] = cb[0];
            out.face[idx(x, y)] = cf[0];
            out.t_m[idx(x, y)] = static_cast<float>(t);
          }
        continue;
      }
      for (int y = y0; y < ye; ++y)
        for (int x = x0; x < xe; ++x) {
          std::int32_t b = -1;
          std::uint8_t f = 0;
          double t = 0;
          if (nearest_among(world, cand, n, o, R * rays.dir(x, y), max_range_m, b, f, t)) {
            out.box[idx(x, y)] = b;
            out.face[idx(x, y)] = f;
            out.t_m[idx(x, y)] = static_cast<float>(t);
          }
        }
    }
  }
}

}  // namespace posed::sim
