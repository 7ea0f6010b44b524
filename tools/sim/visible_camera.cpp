#include "tools/sim/visible_camera.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "tools/sim/moving_objects.hpp"

namespace posed::sim {

VisibleCamera::VisibleCamera(const VisibleCameraConfig& config, const SensorScene& scene,
                             const ClockModel& clock, std::uint64_t seed)
    : config_(config),
      scene_(scene),
      schedule_(clock, config.rate_hz),
      noise_(seed ^ 0xC0FFEEull),
      rays_(config.intrinsics, 1) {}

Duration VisibleCamera::next_send() const {
  // Readout of the rolling-shutter sensor and USB transfer end ~1/2 frame after mid-exposure.
  return schedule_.true_time(index_) + Duration::from_seconds(0.5 * schedule_.period_s());
}

D4xxFrameFacts VisibleCamera::next_metadata(HostTime arrival) const {
  // Auto-exposure is modelled as one amplification (gain_); reported as the real camera splits
  // it: exposure first, up to half the frame interval, then analog gain (64 = 1x).
  D4xxFrameFacts f;
  f.node = D4xxNode::kColour;
  const double interval_us = schedule_.period_s() * 1e6;
  const double exposure_us = interval_us / 2 * std::min(gain_, 1.0);
  const std::int64_t mid_us = next_exposure_mid().ns / 1000;
  f.frame_counter = static_cast<std::uint32_t>(index_);
  f.sensor_timestamp_us = static_cast<std::uint32_t>(mid_us);  // the device counter wraps
  f.pts_us = static_cast<std::uint32_t>(mid_us - std::llround(exposure_us / 2));
  f.exposure_time_us = static_cast<std::uint32_t>(std::llround(exposure_us));
  f.frame_interval_us = static_cast<std::uint32_t>(std::llround(interval_us));
  f.gain = static_cast<std::uint32_t>(std::llround(64 * std::max(gain_, 1.0)));
  f.width_px = static_cast<std::uint16_t>(config_.intrinsics.width);
  f.height_px = static_cast<std::uint16_t>(config_.intrinsics.height);
  f.fps = static_cast<std::uint16_t>(std::lround(config_.rate_hz));
  set_usb_arrival(f, arrival.ns);
  return f;
}

void VisibleCamera::emit(std::vector<std::byte>& out) {
  const World& world = scene_.world;
  const Duration t_true = schedule_.true_time(index_);
  const Eigen::Isometry3d T_map_cam = scene_.trajectory.T_map_base(t_true) * config_.T_base_cam;
  if (scene_.moving != nullptr) scene_.moving->place(t_true);
  render_gbuffer(world, scene_.bvh, rays_, T_map_cam, 150.0, gbuffer_);
  if (scene_.moving != nullptr) scene_.moving->overlay(rays_, T_map_cam, 150.0, gbuffer_);
  const Eigen::Vector3d o = T_map_cam.translation();
  // Lights that matter for this frame: the 8 nearest within 40 m, in float for the pixel loop
  // (positions relative to the camera: millimetres of float rounding at 40 m light nothing).
  std::vector<std::pair<double, const PointLight*>> near;
  for (const PointLight& l : world.lights) {
    const double d = (l.p_map_m - o).norm();
    if (d < 40.0) near.emplace_back(d, &l);
  }
  std::sort(near.begin(), near.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  if (near.size() > 8) near.resize(8);
  std::array<Eigen::Vector3f, 8> light_cam_m;  // light - camera, map axes [m]
  std::array<float, 8> light_intensity{};
  const std::size_t n_lights = near.size();
  for (std::size_t k = 0; k < n_lights; ++k) {
    light_cam_m[k] = (near[k].second->p_map_m - o).cast<float>();
    light_intensity[k] = static_cast<float>(near[k].second->intensity);
  }

  const int W = gbuffer_.width, H = gbuffer_.height;
  const auto N = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
  const Eigen::Matrix3d R = T_map_cam.linear();
  const auto ambient = static_cast<float>(world.ambient);
  const auto headlight = static_cast<float>(world.headlight);
  const auto sky = static_cast<float>(world.sky_radiance);
  // Irradiance at the pixel (x, y) on `face` of `box`, `t_m` along its ray: ambient light, the
  // headlight at the camera, the point lights (Lambert's cosine, inverse square).
  const auto irradiance = [&](int x, int y, std::int32_t box, std::uint8_t face, float t_m) {
    const Eigen::Vector3f n =
        face_normal_map(world.boxes[static_cast<std::size_t>(box)], face).cast<float>();
    const Eigen::Vector3f d = (R * rays_.dir(x, y)).cast<float>();
    const Eigen::Vector3f p_cam = t_m * d;
    float E = ambient + headlight * std::max(0.0f, -n.dot(d)) / (t_m * t_m + 1.0f);
    for (std::size_t k = 0; k < n_lights; ++k) {
      const Eigen::Vector3f to = light_cam_m[k] - p_cam;
      const float d2 = to.squaredNorm();
      const float c = n.dot(to);
      if (c > 0) E += light_intensity[k] * c / (d2 * std::sqrt(d2));
    }
    return E;
  };
  // Irradiance per pixel. It is smooth across a plane (point lights metres away, cells a few
  // centimetres wide), so in cells whose four grid rays met one face it is interpolated from
  // those four corners; elsewhere (edges, corners of boxes) every pixel gets its own.
  const int gw = grid_points(W), gh = grid_points(H);
  grid_irradiance_.resize(static_cast<std::size_t>(gw * gh));
  for (int j = 0; j < gh; ++j)
    for (int i = 0; i < gw; ++i) {
      const int x = grid_pixel(i, W), y = grid_pixel(j, H);
      const std::size_t g = static_cast<std::size_t>(j * gw + i),
                        p = static_cast<std::size_t>(y * W + x);
      grid_irradiance_[g] =
          gbuffer_.grid_box[g] >= 0 && gbuffer_.box[p] == gbuffer_.grid_box[g]
              ? irradiance(x, y, gbuffer_.box[p], gbuffer_.face[p], gbuffer_.t_m[p])
              : -1.0f;  // not usable: the pixel's own hit differs
    }
  irradiance_.resize(N);
  for (int j = 0; j + 1 < gh; ++j)
    for (int i = 0; i + 1 < gw; ++i) {
      const int x0 = grid_pixel(i, W), x1 = grid_pixel(i + 1, W), xe = cell_end(i, gw, W);
      const int y0 = grid_pixel(j, H), y1 = grid_pixel(j + 1, H), ye = cell_end(j, gh, H);
      const std::size_t g = static_cast<std::size_t>(j * gw + i);
      const float e00 = grid_irradiance_[g], e10 = grid_irradiance_[g + 1];
      const float e01 = grid_irradiance_[g + static_cast<std::size_t>(gw)];
      const float e11 = grid_irradiance_[g + static_cast<std::size_t>(gw) + 1];
      const bool smooth = gbuffer_.plane_cell[static_cast<std::size_t>(j * gbuffer_.cells_x + i)] &&
                          e00 >= 0 && e10 >= 0 && e01 >= 0 && e11 >= 0;
      for (int y = y0; y < ye; ++y) {
        const float fy = static_cast<float>(y - y0) / static_cast<float>(y1 - y0);
        const float left = e00 + fy * (e01 - e00), right = e10 + fy * (e11 - e10);
        for (int x = x0; x < xe; ++x) {
          const std::size_t p = static_cast<std::size_t>(y * W + x);
          if (gbuffer_.box[p] < 0) continue;
          irradiance_[p] =
              smooth
                  ? left + static_cast<float>(x - x0) / static_cast<float>(x1 - x0) * (right - left)
                  : irradiance(x, y, gbuffer_.box[p], gbuffer_.face[p], gbuffer_.t_m[p]);
        }
      }
    }
  // Scene radiance (B, G, R) of one pixel: albedo (with the material's texture) times the
  // irradiance, plus emission, tinted.
  const auto radiance = [&](int x, int y, std::size_t i, std::array<float, 3>& L) {
    const std::int32_t box = gbuffer_.box[i];
    if (box < 0) {
      L = {sky, sky, sky};
      return;
    }
    const Box& b = world.boxes[static_cast<std::size_t>(box)];
    const Material& m = world.materials[b.material];
    auto albedo = static_cast<float>(m.albedo);
    if (m.texture != kTexturePlain) {
      const Eigen::Vector3d d = R * rays_.dir(x, y);
      const auto t = static_cast<double>(gbuffer_.t_m[i]);
      const Eigen::Vector3d p = o + t * d;
      const double tv = texture_value(
          m.texture, face_uv_m(b, gbuffer_.face[i], p), static_cast<std::uint32_t>(box),
          pixel_footprint(b, gbuffer_.face[i], d, t, rays_.pixel_angle_rad()));
      albedo *= static_cast<float>(std::max(0.0, 1.0 + m.texture_contrast * 2.0 * (tv - 0.5)));
    }
    const float E = irradiance_[i];
    const auto emission = static_cast<float>(m.emission);
    for (int c = 0; c < 3; ++c)
      L[static_cast<std::size_t>(c)] = static_cast<float>(m.tint_bgr[c]) * (albedo * E + emission);
  };

  // Smoke (smoke.hpp): each pixel keeps exp(-σ·d) of its surface's radiance and sees the
  // smoke's airlight for the rest. Left out entirely without smoke, so the other scenarios'
  // frames are computed exactly as before.
  const double sigma = world.smoke.extinction_per_m(t_true.seconds());
  float airlight = 0;
  if (sigma > 0) {
    double E = world.ambient + world.headlight * headlight_backscatter(sigma);
    for (std::size_t k = 0; k < n_lights; ++k) {
      const double d = near[k].first;
      E += light_intensity[k] * std::exp(-sigma * d) / std::max(d * d, 1.0);
    }
    airlight = static_cast<float>(world.smoke.albedo * E);
  }
  const auto sigma_f = static_cast<float>(sigma);
  const auto through_smoke = [&](std::size_t i, std::array<float, 3>& L) {
    const float T = gbuffer_.box[i] < 0 ? 0.0f : std::exp(-sigma_f * gbuffer_.t_m[i]);
    for (float& c : L) c = c * T + airlight * (1.0f - T);
  };

  // Exposure: this frame with the gain the auto-exposure chose from the previous one.
  const auto scale = static_cast<float>(255.0 * gain_);
  const float read_noise2 = 2.25f * scale / 255.0f;  // (1.5 DN)² amplified by the gain
  // Shot noise variance 0.25 DN per DN of signal, plus read noise amplified by the gain.
  const auto expose = [&](std::array<float, 3>& v) {
    for (float& c : v) {
      c *= scale;
      if (config_.noise) c += std::sqrt(0.25f * std::max(c, 0.0f) + read_noise2) * noise_.normal();
      c = std::clamp(c, 0.0f, 255.0f);
    }
  };
  // BT.601 limited range YUYV: Y0 U Y1 V per pixel pair (rows have an even width), chroma
  // averaged over the pair.
  out.resize(N * 2);
  double sum_y = 0;
  std::array<float, 3> p0{}, p1{};
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x + 1 < W; x += 2) {
      const std::size_t i =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
      radiance(x, y, i, p0);
      radiance(x + 1, y, i + 1, p1);
      if (sigma > 0) {
        through_smoke(i, p0);
        through_smoke(i + 1, p1);
      }
      sum_y += 0.114f * (p0[0] + p1[0]) + 0.587f * (p0[1] + p1[1]) + 0.299f * (p0[2] + p1[2]);
      expose(p0);
      expose(p1);
      const float y0 = 16 + (65.481f * p0[2] + 128.553f * p0[1] + 24.966f * p0[0]) / 255.0f;
      const float y1 = 16 + (65.481f * p1[2] + 128.553f * p1[1] + 24.966f * p1[0]) / 255.0f;
      const float r = 0.5f * (p0[2] + p1[2]), g = 0.5f * (p0[1] + p1[1]),
                  b = 0.5f * (p0[0] + p1[0]);
      const float u = 128 + (-37.797f * r - 74.203f * g + 112.0f * b) / 255.0f;
      const float v = 128 + (112.0f * r - 93.786f * g - 18.214f * b) / 255.0f;
      out[2 * i] = static_cast<std::byte>(to_u8(y0));
      out[2 * i + 1] = static_cast<std::byte>(to_u8(u));
      out[2 * i + 2] = static_cast<std::byte>(to_u8(y1));
      out[2 * i + 3] = static_cast<std::byte>(to_u8(v));
    }
  }
  // Auto-exposure: steer the mean to mid-grey, at most max_gain; one frame of lag like a real AE.
  const double mean = sum_y / static_cast<double>(N);
  const double wanted = mean > 1e-6 ? 0.45 / mean : config_.max_gain;
  gain_ = std::clamp(gain_ * std::pow(wanted / gain_, 0.5), 0.05, config_.max_gain);
  ++index_;
}

}  // namespace posed::sim
