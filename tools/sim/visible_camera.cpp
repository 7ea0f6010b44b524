#include "tools/sim/visible_camera.hpp"

#include <algorithm>
#include <cmath>

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
  const Eigen::Isometry3d T_map_cam =
      scene_.trajectory.T_map_base(schedule_.true_time(index_)) * config_.T_base_cam;
  render_gbuffer(world, scene_.bvh, rays_, T_map_cam, 150.0, gbuffer_);
  const Eigen::Vector3d o = T_map_cam.translation();
  // Lights that matter for this frame: the 8 nearest within 40 m.
  std::vector<std::pair<double, const PointLight*>> near;
  for (const PointLight& l : world.lights) {
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
        L = Eigen::Vector3d::Constant(world.sky_radiance);
      } else {
        const Box& b = world.boxes[static_cast<std::size_t>(gbuffer_.box[i])];
        const Material& m = world.materials[b.material];
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
        double E = world.ambient + world.headlight * std::max(0.0, -n.dot(d)) / (tm * tm + 1.0);
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

}  // namespace posed::sim
