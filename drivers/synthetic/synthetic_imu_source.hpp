#pragma once
// A fake A9 for machines without one: it speaks the A9's real wire format (sensor frames with
// CRC and a 32-bit µs counter) at a configurable rate, generated from a known motion (the
// closed-form circle in core/sim), paced in real time like the device. The pipeline decodes it
// with the real A9 decoder, so the demo and the integration tests exercise the same path as the
// robot.
//
// The counter starts 5 s before its 32-bit wrap, so every run exercises the unwrap.

#include <atomic>
#include <cstdint>
#include <random>
#include <vector>

#include "core/sim/circle_motion.hpp"
#include "drivers/common/source.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::drivers {

struct SyntheticImuConfig {
  sim::CircleMotionConfig motion;
  double rate_hz = 200.0;            ///< [Hz]
  double gyro_noise_density = 0.0;   ///< [rad/s/sqrt(Hz)]
  double accel_noise_density = 0.0;  ///< [m/s^2/sqrt(Hz)]
  std::uint64_t seed = 1;
  /// device counter at the first sample [µs]; default: 5 s before the 32-bit wrap
  std::uint32_t first_counter_us = 0xFFFFFFFFu - 5'000'000u;
  /// false: emit as fast as read() is called (tests); true: pace to the host clock (the device)
  bool real_time = true;
  /// > 0: after this much motion time read() stops returning, like a driver stuck in a blocking
  /// call (it still honours request_stop()); lets tests prove the watchdog notices [s]
  double hang_after_s = 0;
  /// > 0: end of stream after this much motion time, like the end of a recording [s]
  double duration_s = 0;
};

class SyntheticImuSource final : public Source {
 public:
  explicit SyntheticImuSource(const SyntheticImuConfig& config);

  std::string_view name() const override { return "imu"; }
  bool open(std::string& error) override;
  ReadStatus read(RawChunk& chunk, Duration timeout) override;
  void request_stop() override { stop_.store(true, std::memory_order_relaxed); }
  SourceCounters counters() const override;
  bool live() const override { return config_.real_time; }
  /// the A9 serial wire format, as the real device
  std::string_view wire_format(std::uint32_t channel) const override {
    return channel == 0 ? wire::kA9Serial : std::string_view{};
  }

  /// Host time of the motion's t = 0 (valid after open()); the ground truth at host time h is
  /// motion().at(h - motion_start()).
  HostTime motion_start() const { return start_; }
  const sim::CircleMotion& motion() const { return motion_; }

 private:
  SyntheticImuConfig config_;
  sim::CircleMotion motion_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::atomic<bool> stop_{false};
  bool opened_ = false;
  HostTime start_;
  std::int64_t period_ns_ = 0;
  std::uint64_t index_ = 0;
  std::vector<std::uint8_t> frame_;
  AtomicSourceCounters counts_;
};

}  // namespace posed::drivers
