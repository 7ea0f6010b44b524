#include "tools/sim/thermal_camera.hpp"

#include <algorithm>
#include <cmath>

#include "tools/sim/moving_objects.hpp"

namespace posed::sim {

std::string_view to_string(ThermalFormat f) { return f == ThermalFormat::kY16 ? "y16" : "y8"; }

std::optional<ThermalFormat> thermal_format_from_string(std::string_view s) {
  if (s == "y8") return ThermalFormat::kY8;
  if (s == "y16") return ThermalFormat::kY16;
  return std::nullopt;
}

ThermalCamera::ThermalCamera(const ThermalCameraConfig& config, const SensorScene& scene,
                             const ClockModel& clock, std::uint64_t seed)
    : config_(config),
      scene_(scene),
      schedule_(clock, config.rate_hz),
      rng_(seed),
      noise_(seed ^ 0xC0FFEEull),
      radiometry_(config.radiometry),
      rays_(config.intrinsics, 2) {
  const auto W = static_cast<std::size_t>(config_.intrinsics.width);
  const auto H = static_cast<std::size_t>(config_.intrinsics.height);
  fpn_pixel_.resize(W * H);
  fpn_col_.resize(W);
  std::normal_distribution<double> n(0.0, 1.0);
  for (float& v : fpn_pixel_) v = static_cast<float>(n(rng_));
  for (float& v : fpn_col_) v = static_cast<float>(n(rng_));
  std::uniform_real_distribution<double> u(config_.nuc_min_s, config_.nuc_max_s);
  next_nuc_s_ = u(rng_);
  // Full-resolution pixel centres in the half-resolution render, clamped at the borders.
  const auto taps = [](std::size_t full, int half) {
    std::vector<Tap> out(full);
    for (std::size_t i = 0; i < full; ++i) {
      const double s = std::clamp((static_cast<double>(i) - 0.5) / 2.0, 0.0, half - 1.0);
      out[i].i0 = static_cast<std::size_t>(s);
      out[i].i1 = std::min(out[i].i0 + 1, static_cast<std::size_t>(half - 1));
      out[i].f = static_cast<float>(s - static_cast<double>(out[i].i0));
    }
    return out;
  };
  row_taps_ = taps(H, rays_.height());
  col_taps_ = taps(W, rays_.width());
}

Duration ThermalCamera::next_send() const { return schedule_.true_time(index_); }

void ThermalCamera::render_temperatures(Duration t) {
  const World& world = scene_.world;
  const Eigen::Isometry3d T_map_cam = scene_.trajectory.T_map_base(t) * config_.T_base_cam;
  if (scene_.moving != nullptr) scene_.moving->place(t);
  render_gbuffer(world, scene_.bvh, rays_, T_map_cam, 150.0, gbuffer_);
  if (scene_.moving != nullptr) scene_.moving->overlay(rays_, T_map_cam, 150.0, gbuffer_);
  const int w = gbuffer_.width, h = gbuffer_.height;
  temperature_.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  const Eigen::Matrix3d R = T_map_cam.linear();
  const Eigen::Vector3d o = T_map_cam.translation();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      double T;
      if (gbuffer_.box[i] < 0) {
        T = world.sky_temperature_c;
      } else {
        const Box& b = world.boxes[static_cast<std::size_t>(gbuffer_.box[i])];
        const Material& m = world.materials[b.material];
        T = m.temperature_c;
        if (m.texture != kTexturePlain) {
          const Eigen::Vector3d d = R * rays_.dir(x, y);
          const auto range_m = static_cast<double>(gbuffer_.t_m[i]);
          const Eigen::Vector3d p = o + range_m * d;
          T += texture_value(
                   m.texture, face_uv_m(b, gbuffer_.face[i], p),
                   static_cast<std::uint32_t>(gbuffer_.box[i]),
                   pixel_footprint(b, gbuffer_.face[i], d, range_m, rays_.pixel_angle_rad())) -
               0.5;
        }
      }
      temperature_[i] = static_cast<float>(T);
    }
}

void ThermalCamera::emit(std::vector<std::byte>& out) {
  const Duration t = schedule_.true_time(index_);
  const double t_s = t.seconds();
  const auto W = static_cast<std::size_t>(config_.intrinsics.width);
  const auto H = static_cast<std::size_t>(config_.intrinsics.height);
  const bool raw16 = config_.format == ThermalFormat::kY16;
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
  render_temperatures(t);
  const int w = gbuffer_.width;

  // y8: the camera's AGC over the frame's range, smoothed over frames, at least 4 K wide.
  double k = 0;
  if (!raw16) {
    const auto [lo_it, hi_it] = std::minmax_element(temperature_.begin(), temperature_.end());
    double lo = *lo_it, hi = *hi_it;
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
    k = 255.0 / (agc_hi_c_ - agc_lo_c_);
  }

  out.resize(W * H * (raw16 ? 2 : 1));
  const auto fpn =
      static_cast<float>(config_.noise ? config_.fpn_growth_kps * (t_s - last_nuc_s_) + 0.03 : 0.0);
  const auto netd = static_cast<float>(config_.netd_k);
  const auto lo = static_cast<float>(agc_lo_c_), gain = static_cast<float>(k);
  std::vector<float> row(W);
  for (std::size_t y = 0; y < H; ++y) {
    // Bilinear upsampling from the half-resolution render: rows, then columns by table.
    const Tap& ty = row_taps_[y];
    const float* t0 = &temperature_[ty.i0 * static_cast<std::size_t>(w)];
    const float* t1 = &temperature_[ty.i1 * static_cast<std::size_t>(w)];
    for (std::size_t c = 0; c < static_cast<std::size_t>(w); ++c)
      row[c] = t0[c] + ty.f * (t1[c] - t0[c]);
    for (std::size_t x = 0; x < W; ++x) {
      const Tap& tx = col_taps_[x];
      float T = row[tx.i0] + tx.f * (row[tx.i1] - row[tx.i0]);
      if (config_.noise) {
        T += netd * noise_.normal() + fpn * (fpn_pixel_[y * W + x] + 0.7f * fpn_col_[x]);
      }
      const std::size_t i = y * W + x;
      if (raw16) {
        const std::uint16_t counts = radiometry_.counts_u14(T);
        out[2 * i] = static_cast<std::byte>(counts & 0xFF);
        out[2 * i + 1] = static_cast<std::byte>(counts >> 8);
      } else {
        out[i] = static_cast<std::byte>(to_u8((T - lo) * gain));
      }
    }
  }
  last_frame_ = out;
  ++index_;
}

}  // namespace posed::sim
