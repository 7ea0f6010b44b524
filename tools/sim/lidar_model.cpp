#include "tools/sim/lidar_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "drivers/velodyne/position_packet.hpp"
#include "drivers/velodyne/sensor_model.hpp"
#include "tools/sim/moving_objects.hpp"
#include "tools/sim/vlp32c_encoder.hpp"

namespace posed::sim {
namespace vel = drivers::velodyne;
namespace {

constexpr double kCdegToRad = std::numbers::pi / 18000.0;
constexpr std::int64_t kHourNs = 3'600'000'000'000;
/// the largest gap the decoder accepts between firings as a rotation (packet_decoder.cpp)
constexpr std::int32_t kMaxFiringGapCdeg = 100;
/// where the simulated rig is (M2DGR: Shanghai Jiao Tong University, Minhang campus)
constexpr double kLatitudeDeg = 31.0256, kLongitudeDeg = 121.4337;

}  // namespace

LidarModel::LidarModel(const LidarModelConfig& config, const vel::Calibration& calibration,
                       const SensorScene& scene, const ClockModel& clock, std::uint64_t seed)
    : config_(config), scene_(scene), clock_(clock), rng_(seed) {
  const vel::SensorModel& model = *vel::sensor_model(vel::ProductId::kVlp32c);
  distance_resolution_m_ = calibration.distance_resolution_m > 0 ? calibration.distance_resolution_m
                                                                 : model.distance_resolution_m;
  for (std::size_t c = 0; c < 32; ++c) {
    const vel::LaserCorrection& l = calibration.lasers.at(model.laser_of_channel[c]);
    Channel& ch = channels_[c];
    ch.cos_v = std::cos(l.vert_correction_rad);
    ch.sin_v = std::sin(l.vert_correction_rad);
    ch.vert_offset_m = l.vert_offset_m;
    ch.horiz_offset_m = l.horiz_offset_m;
    ch.dist_correction_m = l.dist_correction_m;
    ch.rot_cdeg = l.rot_correction_rad * 18000.0 / std::numbers::pi;
    ch.offset_ns = model.channel_offset_ns[c];
    ch.fraction = static_cast<double>(model.channel_offset_ns[c]) / model.block_period_ns;
  }
  // The first packet starts on the sensor's clock right after true time 0.
  start_device_ = clock_.device_at(Duration::from_ns(0));
}

DeviceTime LidarModel::first_firing(std::uint64_t packet) const {
  const std::int64_t period = vel::sensor_model(vel::ProductId::kVlp32c)->block_period_ns;
  return start_device_ + Duration::from_ns(static_cast<std::int64_t>(packet) * 12 * period);
}

Duration LidarModel::next_data_send() const {
  return clock_.true_at(first_firing(packet_index_ + 1));
}

void LidarModel::emit_data(std::span<std::byte> out, LidarPacketTruth* truth) {
  const std::int32_t period = vel::sensor_model(vel::ProductId::kVlp32c)->block_period_ns;
  const DeviceTime d0 = first_firing(packet_index_);
  Vlp32cPacket packet;
  packet.timestamp_us = static_cast<std::uint32_t>(((d0.ns % kHourNs) + kHourNs) % kHourNs / 1000);

  // Block azimuths as the sensor's encoder reports them, then the rotation per firing exactly as
  // the decoder will interpolate it (the last firing borrows its predecessor's gap).
  const double deg_per_ns = config_.rpm * 6.0 * 1e-9;
  std::array<std::int32_t, 12> az{}, gap{};
  for (std::size_t f = 0; f < 12; ++f) {
    const DeviceTime d = d0 + Duration::from_ns(static_cast<std::int64_t>(f) * period);
    double deg = std::fmod(config_.azimuth0_deg + deg_per_ns * static_cast<double>(d.ns), 360.0);
    if (deg < 0) deg += 360.0;
    az[f] = static_cast<std::int32_t>(std::lround(deg * 100.0)) % 36000;
    packet.blocks[f].azimuth_cdeg = static_cast<std::uint16_t>(az[f]);
  }
  std::int32_t fallback = 0;
  std::array<bool, 12> measured{};
  for (std::size_t f = 0; f + 1 < 12; ++f) {
    const std::int32_t g = (az[f + 1] - az[f] + 36000) % 36000;
    measured[f] = g <= kMaxFiringGapCdeg;
    if (measured[f]) {
      gap[f] = g;
      fallback = g;
    }
  }
  for (std::size_t f = 0; f < 12; ++f) {
    if (!measured[f]) gap[f] = f > 0 ? gap[f - 1] : fallback;
  }

  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const Eigen::Matrix3d R_base_lidar = config_.T_base_lidar.linear();
  const Eigen::Vector3d p_base_lidar = config_.T_base_lidar.translation();
  const double r10_sq = config_.range_10pct_m * config_.range_10pct_m;

  for (std::size_t f = 0; f < 12; ++f) {
    const DeviceTime d = d0 + Duration::from_ns(static_cast<std::int64_t>(f) * period);
    const Duration t_true = clock_.true_at(d);
    if (truth != nullptr) truth->firing_true_ns[f] = t_true.ns;
    const TrajectorySample s = scene_.trajectory.at(t_true);
    if (scene_.moving != nullptr) scene_.moving->place(t_true);
    const Eigen::Matrix3d R_map_base = s.q_map_base.toRotationMatrix();
    const Eigen::Matrix3d R_map_lidar = R_map_base * R_base_lidar;
    const Eigen::Vector3d p_map_lidar = s.p_map_base_m + R_map_base * p_base_lidar;
    // Within one firing (≤ 35 µs) the pose moves to first order: v·dt and ω×·dt.
    const Eigen::Vector3d w_map = R_map_base * s.w_base_radps;
    const Eigen::Vector3d v_map_lidar = s.v_map_mps + w_map.cross(R_map_base * p_base_lidar);
    Vlp32cBlock& block = packet.blocks[f];
    for (std::size_t c = 0; c < 32; ++c) {
      const Channel& ch = channels_[c];
      const double theta = (az[f] + gap[f] * ch.fraction - ch.rot_cdeg) * kCdegToRad;
      const double ct = std::cos(theta), st = std::sin(theta);
      const Eigen::Vector3d d_lidar(ch.cos_v * ct, -ch.cos_v * st, ch.sin_v);
      const Eigen::Vector3d o_lidar(-ch.vert_offset_m * ch.sin_v * ct + ch.horiz_offset_m * st,
                                    ch.vert_offset_m * ch.sin_v * st + ch.horiz_offset_m * ct,
                                    ch.vert_offset_m * ch.cos_v);
      const double dt = ch.offset_ns * 1e-9;
      Eigen::Vector3d dir = R_map_lidar * d_lidar;
      dir += w_map.cross(dir) * dt;
      dir.normalize();
      const Eigen::Vector3d origin = p_map_lidar + v_map_lidar * dt + R_map_lidar * o_lidar;
      ++rays_;
      auto hit = scene_.bvh.cast(origin, dir, config_.max_range_m);
      if (scene_.moving != nullptr) {
        if (auto m = scene_.moving->cast(origin, dir, hit ? hit->t_m : config_.max_range_m))
          hit = m;
      }
      if (truth != nullptr) {
        truth->p_lidar_m[f][c] =
            hit ? Eigen::Vector3f((o_lidar + hit->t_m * d_lidar).cast<float>())
                : Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
        truth->returned[f][c] = false;
      }
      if (!hit) continue;
      const Box& box = scene_.world.boxes[hit->box];
      const Material& m = scene_.world.materials[box.material];
      const double cos_inc = std::abs(face_normal_map(box, hit->face).dot(dir));
      double range = hit->t_m;
      if (config_.noise) {
        // Received power ∝ reflectivity · cos(incidence) / range²; 50 % detection at snr 1.
        const double snr = (m.reflectivity / 10.0) * cos_inc * r10_sq / (range * range);
        const double p_detect =
            (1.0 - config_.random_dropout) / (1.0 + std::exp(-(snr - 1.0) * 8.0));
        if (uniform(rng_) >= p_detect) continue;
        range += config_.range_noise_m * normal(rng_);
      }
      const long raw = std::lround((range - ch.dist_correction_m) / distance_resolution_m_);
      if (raw < 1 || raw > 65535) continue;
      double refl =
          m.reflectivity <= 100.0 ? m.reflectivity * (0.35 + 0.65 * cos_inc) : m.reflectivity;
      if (config_.noise) refl += config_.intensity_noise * normal(rng_);
      block.distance[c] = static_cast<std::uint16_t>(raw);
      block.reflectivity[c] = static_cast<std::uint8_t>(std::clamp(std::lround(refl), 0l, 255l));
      ++returns_;
      if (truth != nullptr) truth->returned[f][c] = true;
    }
  }
  encode_vlp32c_packet(packet, out);
  ++packet_index_;
}

Duration LidarModel::next_position_send() const {
  // Whole seconds of the sensor's clock (its PPS edges), the first one after the start.
  const std::int64_t first_s = start_device_.ns / 1'000'000'000 + 1;
  const DeviceTime d =
      DeviceTime::from_ns((first_s + static_cast<std::int64_t>(position_index_)) * 1'000'000'000);
  return clock_.true_at(d);
}

void LidarModel::emit_position(std::span<std::byte> out) {
  const std::int64_t first_s = start_device_.ns / 1'000'000'000 + 1;
  const std::int64_t sec = first_s + static_cast<std::int64_t>(position_index_);
  // The sensor's clock counts from 2024-06-01T00:00:00Z (the simulated day); GPRMC carries the
  // UTC of this PPS edge, the packet the µs past the hour at which it was sent.
  vel::GprmcFix fix;
  fix.valid = true;
  fix.hour = static_cast<std::uint32_t>((sec / 3600) % 24);
  fix.minute = static_cast<std::uint32_t>((sec / 60) % 60);
  fix.second = static_cast<std::uint32_t>(sec % 60);
  fix.day = 1 + static_cast<std::uint32_t>(sec / 86400);
  fix.month = 6;
  fix.year = 2024;
  fix.latitude_deg = kLatitudeDeg;
  fix.longitude_deg = kLongitudeDeg;
  const std::int64_t d_ns = sec * 1'000'000'000;
  const auto us = static_cast<std::uint32_t>((d_ns % kHourNs) / 1000);
  encode_position_packet(us, vel::PpsStatus::kLocked, make_gprmc(fix), out);
  ++position_index_;
}

}  // namespace posed::sim
