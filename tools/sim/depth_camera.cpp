#include "tools/sim/depth_camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "tools/sim/moving_objects.hpp"

namespace posed::sim {
namespace {

/// Scene light at which a textured surface shows its full pattern to the IR imagers
/// [World::ambient units]: a lit room; a street at night is far below.
constexpr double kLitLevel = 0.1;
/// Pattern contrast that alone, fully lit, lets the matcher lock [0..1].
constexpr double kMatchableContrast = 0.2;
/// A depth step larger than this fraction of the depth is an edge [-].
constexpr double kEdgeStep = 0.05;
/// The IR auto-exposure's target: scene brightness B (albedo-weighted light) times exposure
/// [us], so B = 0.05 (a dim room) gives Intel's default 8.5 ms.
constexpr double kExposureTarget = 0.05 * 8500.0;

}  // namespace

DepthCamera::DepthCamera(const DepthCameraConfig& config, const SensorScene& scene,
                         const ClockModel& clock, std::uint64_t seed, Duration phase)
    : config_(config),
      scene_(scene),
      schedule_(clock, config.rate_hz, phase),
      noise_(seed ^ 0xDE9711ull),
      rays_(config.intrinsics, 1) {}

Duration DepthCamera::next_send() const {
  return schedule_.true_time(index_) + Duration::from_seconds(0.5 * schedule_.period_s());
}

double DepthCamera::depth_rms_m(double z_m) const {
  return z_m * z_m * config_.subpixel_rms_px / (config_.intrinsics.fx * config_.baseline_m);
}

D4xxFrameFacts DepthCamera::next_metadata(HostTime arrival) const {
  D4xxFrameFacts f;
  f.node = D4xxNode::kDepth;
  const std::int64_t mid_us = schedule_.device(index_).ns / 1000;
  f.frame_counter = static_cast<std::uint32_t>(index_);
  f.sensor_timestamp_us = static_cast<std::uint32_t>(mid_us);  // the device counter wraps
  f.pts_us = static_cast<std::uint32_t>(mid_us - std::llround(exposure_us_ / 2));
  f.exposure_time_us = static_cast<std::uint32_t>(std::llround(exposure_us_));
  f.frame_interval_us = static_cast<std::uint32_t>(std::llround(schedule_.period_s() * 1e6));
  f.gain = static_cast<std::uint32_t>(std::llround(gain_));
  f.laser_power_mw = static_cast<std::uint32_t>(std::llround(config_.laser_power_mw));
  f.width_px = static_cast<std::uint16_t>(config_.intrinsics.width);
  f.height_px = static_cast<std::uint16_t>(config_.intrinsics.height);
  f.fps = static_cast<std::uint16_t>(std::lround(config_.rate_hz));
  set_usb_arrival(f, arrival.ns);
  return f;
}

void DepthCamera::mark_occlusions() {
  // The right imager sits `baseline` along +x: a pixel at column x appears there at
  // x - d, d = fx·b/z. A nearer surface to its right that lands at or left of that column
  // hides it from the right imager, and the ASIC's left-right check rejects the match.
  const int W = gbuffer_.width, H = gbuffer_.height;
  const double fb = config_.intrinsics.fx * config_.baseline_m;
  for (int y = 0; y < H; ++y) {
    double leftmost_right_col = std::numeric_limits<double>::infinity();
    for (int x = W - 1; x >= 0; --x) {
      const std::size_t i =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
      if (z_m_[i] <= 0.0f) continue;
      const double right_col = x - fb / z_m_[i];
      if (pixel_[i] == DepthPixel::kValid &&
          (right_col < -0.5 || leftmost_right_col < right_col - 0.5)) {
        pixel_[i] = DepthPixel::kOccluded;
      }
      leftmost_right_col = std::min(leftmost_right_col, right_col);
    }
  }
}

void DepthCamera::mark_edges() {
  // The matching window (a few pixels) straddles both surfaces of a depth step; the pixels on
  // the far side then match either surface or none: half of them are rejected.
  const int W = gbuffer_.width, H = gbuffer_.height;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::size_t i =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
      if (pixel_[i] != DepthPixel::kValid) continue;
      const float z = z_m_[i];
      bool far_side = false;
      for (const auto& [dx, dy] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
        const int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
        const float zn = z_m_[static_cast<std::size_t>(ny) * static_cast<std::size_t>(W) +
                              static_cast<std::size_t>(nx)];
        far_side = far_side || (zn > 0.0f && zn < z * (1.0f - static_cast<float>(kEdgeStep)));
      }
      if (far_side && (!config_.noise || noise_.uniform() < 0.5f)) pixel_[i] = DepthPixel::kEdge;
    }
}

void DepthCamera::emit(std::vector<std::byte>& out, DepthFrameTruth* truth) {
  const World& world = scene_.world;
  const Eigen::Isometry3d T_map_depth =
      scene_.trajectory.T_map_base(schedule_.true_time(index_)) * config_.T_base_depth;
  if (scene_.moving != nullptr) scene_.moving->place(schedule_.true_time(index_));
  render_gbuffer(world, scene_.bvh, rays_, T_map_depth, 150.0, gbuffer_);
  if (scene_.moving != nullptr) scene_.moving->overlay(rays_, T_map_depth, 150.0, gbuffer_);
  const int W = gbuffer_.width, H = gbuffer_.height;
  const auto N = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
  z_m_.resize(N);
  pixel_.resize(N);
  const Eigen::Matrix3d R = T_map_depth.linear();
  const double deg = std::numbers::pi / 180.0;
  const double cos_limit = std::cos(config_.grazing_limit_deg * deg);
  const double cos_ramp = std::cos((config_.grazing_limit_deg - 10.0) * deg);
  const double laser = config_.laser_power_mw / 150.0;
  const double proj_r2 = config_.projector_range_m * config_.projector_range_m;
  double brightness_sum = 0;

  // Geometry and texture: which pixels the matcher can lock onto.
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::size_t i =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
      if (gbuffer_.box[i] < 0) {
        z_m_[i] = 0.0f;
        pixel_[i] = DepthPixel::kNoHit;
        continue;
      }
      const Eigen::Vector3d& d = rays_.dir(x, y);
      const double z = gbuffer_.t_m[i] * d.z();
      z_m_[i] = static_cast<float>(z);
      const Box& b = world.boxes[static_cast<std::size_t>(gbuffer_.box[i])];
      const Material& m = world.materials[b.material];
      const double cos_inc = std::abs(face_normal_map(b, gbuffer_.face[i]).dot(R * d));
      const double z2 = z * z;
      const double light = world.ambient + world.headlight * cos_inc / (z2 + 1.0);
      const double projector = (m.albedo / 0.5) * laser * proj_r2 / z2;
      brightness_sum += m.albedo * (light + 0.1 * laser * cos_inc / std::max(z2, 0.25));
      if (z < config_.min_range_m || z > config_.max_range_m) {
        pixel_[i] = DepthPixel::kOutOfRange;
        continue;
      }
      if (cos_inc < cos_limit ||
          (config_.noise && cos_inc < cos_ramp &&
           noise_.uniform() < (cos_ramp - cos_inc) / (cos_ramp - cos_limit))) {
        pixel_[i] = DepthPixel::kGrazing;
        continue;
      }
      const double contrast = m.texture == kTexturePlain ? 0.0 : m.texture_contrast;
      const double passive = contrast * std::min(1.0, light / kLitLevel) / kMatchableContrast;
      // Matching succeeds somewhere around score 1; the exact threshold varies pixel to pixel.
      const double threshold = config_.noise ? 0.7 + 0.6 * noise_.uniform() : 1.0;
      pixel_[i] = passive + projector >= threshold ? DepthPixel::kValid : DepthPixel::kLowTexture;
    }
  mark_occlusions();
  mark_edges();

  // Measurement: the matched disparity, back to depth, in depth units.
  const double fb = config_.intrinsics.fx * config_.baseline_m;
  out.resize(2 * N);
  for (std::size_t i = 0; i < N; ++i) {
    std::uint16_t counts = 0;
    if (pixel_[i] == DepthPixel::kValid) {
      double disparity = fb / z_m_[i];
      if (config_.noise) {
        if (noise_.uniform() < static_cast<float>(config_.speckle_fraction)) {
          const double wrong = 1.0 + 5.0 * noise_.uniform();
          disparity += noise_.uniform() < 0.5f ? -wrong : wrong;
          pixel_[i] = DepthPixel::kSpeckle;
        } else {
          disparity += config_.subpixel_rms_px * noise_.normal();
        }
      }
      const double z = disparity > 0 ? fb / disparity : 0.0;
      const double units = z / config_.depth_unit_m;
      if (z < config_.min_range_m || z > config_.max_range_m || units > 65535.0) {
        pixel_[i] = DepthPixel::kOutOfRange;
      } else {
        counts = static_cast<std::uint16_t>(units + 0.5);
      }
    }
    out[2 * i] = static_cast<std::byte>(counts & 0xFF);
    out[2 * i + 1] = static_cast<std::byte>(counts >> 8);
  }

  // Scene-level IR auto-exposure for the next frame (one frame of lag, like the colour AE):
  // exposure up to half the frame interval, then gain (16 = 1x, at most 248).
  const double brightness = std::max(brightness_sum / static_cast<double>(N), 1e-6);
  const double wanted_us = kExposureTarget / brightness;
  const double max_us = 0.5 * schedule_.period_s() * 1e6;
  exposure_us_ = std::clamp(wanted_us, 20.0, max_us);
  gain_ = std::clamp(16.0 * wanted_us / max_us, 16.0, 248.0);

  if (truth != nullptr) {
    truth->z_m = z_m_;
    truth->pixel = pixel_;
    truth->T_map_depth = T_map_depth;
  }
  ++index_;
}

}  // namespace posed::sim
