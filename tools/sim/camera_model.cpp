#include "tools/sim/camera_model.hpp"

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

std::uint8_t to_u8(double v) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0l, 255l));
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

// ---- visible -------------------------------------------------------------------------------

VisibleCamera::VisibleCamera(const VisibleCameraConfig& config, const World& world, const Bvh& bvh,
                             const Trajectory& trajectory, const ClockModel& clock,
                             std::uint64_t seed)
    : config_(config),
      world_(world),
      bvh_(bvh),
      trajectory_(trajectory),
      clock_(clock),
      rng_(seed),
      noise_(seed ^ 0xC0FFEEull),
      rays_(config.intrinsics, 1) {
  start_device_ = clock_.device_at(Duration::from_ns(0));
}

DeviceTime VisibleCamera::exposure_mid(std::uint64_t k) const {
  return start_device_ +
         Duration::from_ns(std::llround(static_cast<double>(k + 1) * 1e9 / config_.rate_hz));
}

Duration VisibleCamera::next_send() const {
  // Readout of the rolling-shutter sensor and USB transfer end ~1/2 frame after mid-exposure.
  return clock_.true_at(exposure_mid(index_)) + Duration::from_seconds(0.5 / config_.rate_hz);
}

void VisibleCamera::emit(std::vector<std::byte>& out) {
  const Duration t = clock_.true_at(exposure_mid(index_));
  const TrajectorySample s = trajectory_.at(t);
  const Eigen::Isometry3d T_map_base = Eigen::Translation3d(s.p_map_base_m) * s.q_map_base;
  const Eigen::Isometry3d T_map_cam = T_map_base * config_.T_base_cam;
  render_gbuffer(world_, bvh_, rays_, T_map_cam, 150.0, gbuffer_);
  const Eigen::Vector3d o = T_map_cam.translation();
  // Lights that matter for this frame: the 8 nearest within 40 m.
  std::vector<std::pair<double, const PointLight*>> near;
  for (const PointLight& l : world_.lights) {
    const double d = (l.p_map_m - o).norm();
    if (d < 40.0) near.emplace_back(d, &l);
  }
  std::sort(near.begin(), near.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  if (near.size() > 8) near.resize(8);

  const int W = gbuffer_.width, H = gbuffer_.height;
  const auto N = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
  radiance_.resize(3 * N);
  const Eigen::Matrix3d R = T_map_cam.linear();
  double sum_y = 0;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const std::size_t i =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
      Eigen::Vector3d L;
      if (gbuffer_.box[i] < 0) {
        L = Eigen::Vector3d::Constant(world_.sky_radiance);
      } else {
        const Box& b = world_.boxes[static_cast<std::size_t>(gbuffer_.box[i])];
        const Material& m = world_.materials[b.material];
        const Eigen::Vector3d d = R * rays_.dir(x, y);
        const double tm = gbuffer_.t_m[i];
        const Eigen::Vector3d p = o + tm * d;
        const Eigen::Vector3d n = face_normal_map(b, gbuffer_.face[i]);
        double albedo = m.albedo;
        if (m.texture != kTexturePlain) {
          const double tv = texture_value(m.texture, face_uv_m(b, gbuffer_.face[i], p),
                                          static_cast<std::uint32_t>(gbuffer_.box[i]));
          albedo *= std::max(0.0, 1.0 + m.texture_contrast * 2.0 * (tv - 0.5));
        }
        double E = world_.ambient + world_.headlight * std::max(0.0, -n.dot(d)) / (tm * tm + 1.0);
        for (const auto& [dist, light] : near) {
          const Eigen::Vector3d to = light->p_map_m - p;
          const double d2 = to.squaredNorm();
          const double c = n.dot(to) / std::sqrt(d2);
          if (c > 0) E += light->intensity * c / d2;
        }
        L = m.tint_bgr * (albedo * E + m.emission);
      }
      radiance_[3 * i] = static_cast<float>(L[0]);
      radiance_[3 * i + 1] = static_cast<float>(L[1]);
      radiance_[3 * i + 2] = static_cast<float>(L[2]);
      sum_y += 0.114 * L[0] + 0.587 * L[1] + 0.299 * L[2];
    }
  }
  // Auto-exposure: steer the mean to mid-grey, at most max_gain; one frame of lag like a real AE.
  const double scale = 255.0 * gain_;
  const double mean = sum_y / static_cast<double>(N);
  const double wanted = mean > 1e-6 ? 0.45 / mean : config_.max_gain;
  gain_ = std::clamp(gain_ * std::pow(wanted / gain_, 0.5), 0.05, config_.max_gain);

  out.resize(N * 2);
  const double read_noise2 = 2.25 * scale / 255.0;  // (1.5 DN)² amplified by the gain
  auto pixel_bgr = [&](std::size_t i, double& B, double& G, double& Rr) {
    B = radiance_[3 * i] * scale;
    G = radiance_[3 * i + 1] * scale;
    Rr = radiance_[3 * i + 2] * scale;
    if (config_.noise) {
      // Shot noise variance 0.25 DN per DN of signal, plus read noise amplified by the gain.
      B += std::sqrt(0.25 * std::max(B, 0.0) + read_noise2) * noise_.normal();
      G += std::sqrt(0.25 * std::max(G, 0.0) + read_noise2) * noise_.normal();
      Rr += std::sqrt(0.25 * std::max(Rr, 0.0) + read_noise2) * noise_.normal();
    }
    B = std::clamp(B, 0.0, 255.0);
    G = std::clamp(G, 0.0, 255.0);
    Rr = std::clamp(Rr, 0.0, 255.0);
  };
  // BT.601 limited range YUYV: Y0 U Y1 V per pixel pair, chroma averaged over the pair.
  for (std::size_t i = 0; i + 1 < N; i += 2) {
    double b0, g0, r0, b1, g1, r1;
    pixel_bgr(i, b0, g0, r0);
    pixel_bgr(i + 1, b1, g1, r1);
    const double y0 = 16 + (65.481 * r0 + 128.553 * g0 + 24.966 * b0) / 255.0;
    const double y1 = 16 + (65.481 * r1 + 128.553 * g1 + 24.966 * b1) / 255.0;
    const double r = 0.5 * (r0 + r1), g = 0.5 * (g0 + g1), b = 0.5 * (b0 + b1);
    const double u = 128 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255.0;
    const double v = 128 + (112.0 * r - 93.786 * g - 18.214 * b) / 255.0;
    out[2 * i] = static_cast<std::byte>(to_u8(y0));
    out[2 * i + 1] = static_cast<std::byte>(to_u8(u));
    out[2 * i + 2] = static_cast<std::byte>(to_u8(y1));
    out[2 * i + 3] = static_cast<std::byte>(to_u8(v));
  }
  ++index_;
}

// ---- thermal -------------------------------------------------------------------------------

ThermalCamera::ThermalCamera(const ThermalCameraConfig& config, const World& world, const Bvh& bvh,
                             const Trajectory& trajectory, const ClockModel& clock,
                             std::uint64_t seed)
    : config_(config),
      world_(world),
      bvh_(bvh),
      trajectory_(trajectory),
      clock_(clock),
      rng_(seed),
      noise_(seed ^ 0xC0FFEEull),
      rays_(config.intrinsics, 2) {
  start_device_ = clock_.device_at(Duration::from_ns(0));
  const auto W = static_cast<std::size_t>(config_.intrinsics.width);
  const auto H = static_cast<std::size_t>(config_.intrinsics.height);
  fpn_pixel_.resize(W * H);
  fpn_col_.resize(W);
  std::normal_distribution<double> n(0.0, 1.0);
  for (float& v : fpn_pixel_) v = static_cast<float>(n(rng_));
  for (float& v : fpn_col_) v = static_cast<float>(n(rng_));
  std::uniform_real_distribution<double> u(config_.nuc_min_s, config_.nuc_max_s);
  next_nuc_s_ = u(rng_);
}

DeviceTime ThermalCamera::exposure_mid(std::uint64_t k) const {
  return start_device_ +
         Duration::from_ns(std::llround(static_cast<double>(k + 1) * 1e9 / config_.rate_hz));
}

Duration ThermalCamera::next_send() const { return clock_.true_at(exposure_mid(index_)); }

void ThermalCamera::emit(std::vector<std::byte>& out) {
  const Duration t = clock_.true_at(exposure_mid(index_));
  const double t_s = t.seconds();
  const auto W = static_cast<std::size_t>(config_.intrinsics.width);
  const auto H = static_cast<std::size_t>(config_.intrinsics.height);
  out.resize(W * H);
  // NUC: the shutter closes for 0.3 s (the video freezes), then the pattern starts afresh.
  if (config_.noise && t_s >= next_nuc_s_) {
    if (t_s < next_nuc_s_ + 0.3 && !last_frame_.empty()) {
      out = last_frame_;
      ++index_;
      return;
    }
    last_nuc_s_ = next_nuc_s_ + 0.3;
    next_nuc_s_ = last_nuc_s_ + std::uniform_real_distribution<double>(config_.nuc_min_s,
                                                                       config_.nuc_max_s)(rng_);
    ++nucs_;
    std::normal_distribution<double> n(0.0, 1.0);
    for (float& v : fpn_pixel_) v = static_cast<float>(n(rng_));
    for (float& v : fpn_col_) v = static_cast<float>(n(rng_));
  }
  const TrajectorySample s = trajectory_.at(t);
  const Eigen::Isometry3d T_map_base = Eigen::Translation3d(s.p_map_base_m) * s.q_map_base;
  const Eigen::Isometry3d T_map_cam = T_map_base * config_.T_base_cam;
  render_gbuffer(world_, bvh_, rays_, T_map_cam, 150.0, gbuffer_);
  const int w = gbuffer_.width, h = gbuffer_.height;
  temperature_.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  const Eigen::Matrix3d R = T_map_cam.linear();
  const Eigen::Vector3d o = T_map_cam.translation();
  double lo = 1e9, hi = -1e9;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      double T;
      if (gbuffer_.box[i] < 0) {
        T = world_.sky_temperature_c;
      } else {
        const Box& b = world_.boxes[static_cast<std::size_t>(gbuffer_.box[i])];
        const Material& m = world_.materials[b.material];
        T = m.temperature_c;
        if (m.texture != kTexturePlain) {
          const Eigen::Vector3d p =
              o + static_cast<double>(gbuffer_.t_m[i]) * (R * rays_.dir(x, y));
          T += (texture_value(m.texture, face_uv_m(b, gbuffer_.face[i], p),
                              static_cast<std::uint32_t>(gbuffer_.box[i])) -
                0.5);
        }
      }
      temperature_[i] = static_cast<float>(T);
      lo = std::min(lo, T);
      hi = std::max(hi, T);
    }
  // AGC: the frame's range, smoothed over frames, at least 4 K wide.
  if (hi - lo < 4.0) {
    const double mid = 0.5 * (hi + lo);
    lo = mid - 2.0;
    hi = mid + 2.0;
  }
  if (!agc_init_) {
    agc_lo_c_ = lo;
    agc_hi_c_ = hi;
    agc_init_ = true;
  }
  agc_lo_c_ += 0.2 * (lo - agc_lo_c_);
  agc_hi_c_ += 0.2 * (hi - agc_hi_c_);
  const double k = 255.0 / (agc_hi_c_ - agc_lo_c_);
  const double fpn = config_.noise ? config_.fpn_growth_kps * (t_s - last_nuc_s_) + 0.03 : 0.0;
  for (std::size_t y = 0; y < H; ++y) {
    // Bilinear upsampling from the half-resolution render.
    const double sy = std::clamp((static_cast<double>(y) - 0.5) / 2.0, 0.0, h - 1.0);
    const auto y0 = static_cast<std::size_t>(sy);
    const std::size_t y1 = std::min(y0 + 1, static_cast<std::size_t>(h - 1));
    const double fy = sy - static_cast<double>(y0);
    for (std::size_t x = 0; x < W; ++x) {
      const double sx = std::clamp((static_cast<double>(x) - 0.5) / 2.0, 0.0, w - 1.0);
      const auto x0 = static_cast<std::size_t>(sx);
      const std::size_t x1 = std::min(x0 + 1, static_cast<std::size_t>(w - 1));
      const double fx = sx - static_cast<double>(x0);
      const auto row0 = y0 * static_cast<std::size_t>(w), row1 = y1 * static_cast<std::size_t>(w);
      double T = (temperature_[row0 + x0] * (1 - fx) + temperature_[row0 + x1] * fx) * (1 - fy) +
                 (temperature_[row1 + x0] * (1 - fx) + temperature_[row1 + x1] * fx) * fy;
      if (config_.noise) {
        T += config_.netd_k * noise_.normal() + fpn * (fpn_pixel_[y * W + x] + 0.7 * fpn_col_[x]);
      }
      out[y * W + x] = static_cast<std::byte>(to_u8((T - agc_lo_c_) * k));
    }
  }
  last_frame_ = out;
  ++index_;
}

}  // namespace posed::sim
