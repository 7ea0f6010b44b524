#include "tools/sim/imu_model.hpp"

#include <cmath>

namespace posed::sim {

ImuModel::ImuModel(const ImuModelConfig& config, const Trajectory& trajectory,
                   const ClockModel& clock, std::uint64_t seed)
    : config_(config), trajectory_(trajectory), schedule_(clock, config.rate_hz), rng_(seed) {
  if (config_.noise) {
    std::normal_distribution<double> n(0.0, 1.0);
    for (int a = 0; a < 3; ++a) gyro_bias_[a] = config_.gyro_bias_sigma_radps * n(rng_);
    for (int a = 0; a < 3; ++a) accel_bias_[a] = config_.accel_bias_sigma_mps2 * n(rng_);
  }
}

Duration ImuModel::next_send() const { return schedule_.true_time(index_); }

std::size_t ImuModel::emit(std::span<std::uint8_t> out) {
  const DeviceTime d = schedule_.device(index_);
  const Duration t = schedule_.true_time(index_);
  const TrajectorySample s = trajectory_.at(t);
  Eigen::Vector3d w = config_.gyro_scale_misalignment * s.w_base_radps;
  Eigen::Vector3d f = config_.accel_scale_misalignment * s.f_base_mps2;
  if (config_.noise) {
    // Discrete equivalents of the continuous densities at the sample period dt:
    // white σ = density/√dt, bias step σ = walk·√dt.
    const double dt = 1.0 / config_.rate_hz;
    std::normal_distribution<double> n(0.0, 1.0);
    for (int a = 0; a < 3; ++a) gyro_bias_[a] += config_.gyro_random_walk * std::sqrt(dt) * n(rng_);
    for (int a = 0; a < 3; ++a)
      accel_bias_[a] += config_.accel_random_walk * std::sqrt(dt) * n(rng_);
    for (int a = 0; a < 3; ++a)
      w[a] += gyro_bias_[a] + config_.gyro_noise_density / std::sqrt(dt) * n(rng_);
    for (int a = 0; a < 3; ++a)
      f[a] += accel_bias_[a] + config_.accel_noise_density / std::sqrt(dt) * n(rng_);
  }
  const Eigen::Vector3d mag = s.q_map_base.conjugate() * config_.mag_map;
  // The A9's counter is µs since power-on, 32 bits (wraps every 71.6 min).
  const auto counter =
      static_cast<std::uint32_t>(static_cast<std::uint64_t>(d.ns / 1000) & 0xFFFF'FFFFull);
  const drivers::a9::A9SensorFrame frame =
      drivers::a9::a9_frame_from_si(w, f, mag, counter, config_.mounting);
  last_.t_true_ns = t.ns;
  last_.w_true_radps = s.w_base_radps;
  last_.f_true_mps2 = s.f_base_mps2;
  last_.gyro_bias_radps = gyro_bias_;
  last_.accel_bias_mps2 = accel_bias_;
  last_.w_meas_radps = w;
  last_.f_meas_mps2 = f;
  last_.counter_us = counter;
  ++index_;
  return drivers::a9::encode_a9_sensor_frame(frame, out);
}

}  // namespace posed::sim
