#include "drivers/synthetic/synthetic_imu_source.hpp"

#include <cmath>
#include <thread>

#include "drivers/common/host_clock.hpp"
#include "drivers/imu/a9_protocol.hpp"

namespace posed::drivers {

SyntheticImuSource::SyntheticImuSource(const SyntheticImuConfig& config)
    : config_(config),
      motion_(config.motion),
      rng_(config.seed),
      period_ns_(static_cast<std::int64_t>(std::llround(1e9 / config.rate_hz))),
      frame_(a9::kSensorFrameSize) {}

bool SyntheticImuSource::open(std::string& /*error*/) {
  if (!opened_) {
    start_ = config_.real_time ? host_now() : HostTime::from_ns(0);
    opened_ = true;
  }
  return true;
}

ReadStatus SyntheticImuSource::read(RawChunk& chunk, Duration timeout) {
  if (stop_.load(std::memory_order_relaxed)) return ReadStatus::kEndOfStream;
  const Duration t_sample = Duration::from_ns(static_cast<std::int64_t>(index_) * period_ns_);
  const HostTime due = start_ + t_sample;
  if (config_.duration_s > 0 && t_sample.seconds() > config_.duration_s) {
    return ReadStatus::kEndOfStream;
  }
  if (config_.hang_after_s > 0 && t_sample.seconds() >= config_.hang_after_s) {
    while (!stop_.load(std::memory_order_relaxed)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return ReadStatus::kEndOfStream;
  }
  HostTime receive = due;
  if (config_.real_time) {
    const HostTime now = host_now();
    if (due - now > timeout) {
      std::this_thread::sleep_for(std::chrono::nanoseconds(timeout.ns));
      return ReadStatus::kTimeout;
    }
    if (due > now) std::this_thread::sleep_for(std::chrono::nanoseconds((due - now).ns));
    receive = host_now();
  }

  const sim::MotionSample truth = motion_.at(t_sample);
  // Discrete white noise: density * sqrt(rate) per sample.
  const double sqrt_rate = std::sqrt(config_.rate_hz);
  const double sigma_w = config_.gyro_noise_density * sqrt_rate;
  const double sigma_f = config_.accel_noise_density * sqrt_rate;
  const Eigen::Vector3d w =
      truth.w_base_radps + sigma_w * Eigen::Vector3d(normal_(rng_), normal_(rng_), normal_(rng_));
  const Eigen::Vector3d f =
      truth.f_base_mps2 + sigma_f * Eigen::Vector3d(normal_(rng_), normal_(rng_), normal_(rng_));
  // The device counter: µs, wrapping at 2^32 (the unsigned arithmetic wraps it).
  const auto counter_us = static_cast<std::uint32_t>(
      config_.first_counter_us + static_cast<std::uint32_t>(t_sample.ns / 1000));
  // Earth's field (about 50 µT, pointing north and down), as the device would see it level.
  const Eigen::Vector3d mag = truth.q_map_base.conjugate() * Eigen::Vector3d(0, 0.3, -0.4);
  const a9::A9SensorFrame frame = a9::a9_frame_from_si(w, f, mag, counter_us);
  const std::size_t n = a9::encode_a9_sensor_frame(frame, frame_);

  ++index_;
  counts_.count_chunk(n);
  chunk.bytes = std::as_bytes(std::span<const std::uint8_t>(frame_.data(), n));
  chunk.host_receive = receive;
  chunk.channel = 0;
  return ReadStatus::kData;
}

SourceCounters SyntheticImuSource::counters() const { return counts_.snapshot(); }

}  // namespace posed::drivers
