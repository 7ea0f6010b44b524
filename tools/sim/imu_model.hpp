#pragma once
// The Handsfree A9 on the vehicle: the trajectory's exact angular rate and specific force at each
// sample's true time, plus white noise and a bias random walk (continuous-time densities, as
// Kalibr/VINS state them), quantised to float32 and framed by drivers/imu/a9_protocol's encoder.
// Samples are regular on the A9's own µs counter (so the host sees its drift).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <random>
#include <span>

#include "core/time.hpp"
#include "drivers/imu/a9_protocol.hpp"
#include "tools/sim/clock_model.hpp"
#include "tools/sim/trajectory.hpp"

namespace posed::sim {

struct ImuModelConfig {
  /// sample rate on the device clock [Hz]
  double rate_hz = 150.0;
  /// [rad/s/√Hz]
  double gyro_noise_density = 2.3417543020438883e-03;
  /// [rad/s²/√Hz]
  double gyro_random_walk = 1.4428407712885209e-05;
  /// [m/s²/√Hz]
  double accel_noise_density = 3.7686306102624571e-02;
  /// [m/s³/√Hz]
  double accel_random_walk = 1.1416642385952368e-03;
  /// 1σ of the bias at power-on, per axis [rad/s]
  double gyro_bias_sigma_radps = 2e-3;
  /// 1σ of the bias at power-on, per axis [m/s²]
  double accel_bias_sigma_mps2 = 3e-2;
  /// false: ideal samples (only float32 quantisation), for integration tests
  bool noise = true;
  /// how the device is mounted in the IMU frame
  drivers::a9::A9Mounting mounting;
  /// Earth's field in map, device units (the A9 passes the magnetometer through unscaled)
  Eigen::Vector3d mag_map{0.33, 0.0, -0.70};
  /// measured = M · true before bias and noise: scale factors on the diagonal, axis
  /// misalignment off it (identity: a perfectly calibrated IMU; --miscalibrate sets them)
  Eigen::Matrix3d gyro_scale_misalignment = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d accel_scale_misalignment = Eigen::Matrix3d::Identity();
};

/// The last emitted sample, for tests.
struct ImuSampleTruth {
  /// true time of the sample [ns since the simulation start]
  std::int64_t t_true_ns = 0;
  /// exact values in the IMU frame
  Eigen::Vector3d w_true_radps, f_true_mps2;
  /// current biases [rad/s], [m/s²]
  Eigen::Vector3d gyro_bias_radps, accel_bias_mps2;
  /// what the frame carries, back in SI, IMU frame
  Eigen::Vector3d w_meas_radps, f_meas_mps2;
  /// the device counter in the frame [µs]
  std::uint32_t counter_us = 0;
};

class ImuModel {
 public:
  ImuModel(const ImuModelConfig& config, const Trajectory& trajectory, const ClockModel& clock,
           std::uint64_t seed);

  /// True time of the next sample.
  Duration next_send() const;
  /// Writes the next 49-byte sensor frame into `out`; returns bytes written.
  std::size_t emit(std::span<std::uint8_t> out);
  const ImuSampleTruth& last() const { return last_; }
  std::uint64_t samples() const { return index_; }

 private:
  ImuModelConfig config_;
  const Trajectory& trajectory_;
  DeviceSchedule schedule_;  // samples regular on the A9's counter
  std::mt19937_64 rng_;
  std::uint64_t index_ = 0;
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero(), accel_bias_ = Eigen::Vector3d::Zero();
  ImuSampleTruth last_;
};

}  // namespace posed::sim
