#pragma once
// The D435i's own IMU (a Bosch BMI055 behind USB HID) on the vehicle, as Linux's
// hid-sensor-accel-3d / hid-sensor-gyro-3d deliver it: 24-byte IIO scan records (x, y, z as
// le:s16/32 at 0, 4, 8; le:s64 in_timestamp [ns] at 16) on two channels, accel at 250 Hz and gyro
// at 200 Hz, both timed by the D435i's clock. Values in the sensor's axes (diag(-1, 1, -1) of the
// depth frame, which the decoder undoes), LSB 0.001 g and 0.1 deg/s as librealsense scales them.
// The readings are those of a point rigidly on the vehicle where the D435i's IMU sits (lever-arm
// terms included), plus white noise, a power-on bias and its random walk.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/time.hpp"
#include "tools/sim/clock_model.hpp"
#include "tools/sim/trajectory.hpp"

namespace posed::sim {

struct RealsenseImuModelConfig {
  /// the D435i's IMU in base_link; its axes are the depth frame's (x right, y down, z forward)
  Eigen::Isometry3d T_base_rsimu = Eigen::Isometry3d::Identity();
  double accel_rate_hz = 250.0;  ///< on the device clock [Hz]
  double gyro_rate_hz = 200.0;   ///< [Hz]
  /// BMI055 datasheet: gyro 0.014 deg/s/sqrt(Hz), accel 150 ug/sqrt(Hz)
  double gyro_noise_density = 2.44e-4;   ///< [rad/s/sqrt(Hz)]
  double accel_noise_density = 1.47e-3;  ///< [m/s^2/sqrt(Hz)]
  double gyro_random_walk = 1.0e-5;      ///< [rad/s^2/sqrt(Hz)]
  double accel_random_walk = 5.0e-4;     ///< [m/s^3/sqrt(Hz)]
  /// 1 sigma per axis of what a factory-calibrated unit keeps at power-on
  double gyro_bias_sigma_radps = 3e-3;
  double accel_bias_sigma_mps2 = 5e-2;
  /// false: ideal readings (only the LSB quantisation)
  bool noise = true;
};

/// Wire formats of the two channels, as RealsenseImuSource describes a D435i's devices.
std::string realsense_accel_wire_format();
std::string realsense_gyro_wire_format();

class RealsenseImuModel {
 public:
  /// `clock`: the D435i's clock (its hardware timestamps are in ns on it).
  RealsenseImuModel(const RealsenseImuModelConfig& config, const Trajectory& trajectory,
                    const ClockModel& clock, std::uint64_t seed);

  /// True time of the next accel / gyro record.
  Duration next_accel() const { return accel_schedule_.true_time(accel_index_); }
  Duration next_gyro() const { return gyro_schedule_.true_time(gyro_index_); }
  /// The next 24-byte record of each channel.
  std::vector<std::byte> emit_accel();
  std::vector<std::byte> emit_gyro();

  /// The true angular rate and specific force of the D435i's IMU in its (depth) axes at `t`.
  void truth_at(Duration t, Eigen::Vector3d& w_rsimu_radps, Eigen::Vector3d& f_rsimu_mps2) const;
  const Eigen::Vector3d& gyro_bias_radps() const { return gyro_bias_; }
  const Eigen::Vector3d& accel_bias_mps2() const { return accel_bias_; }

 private:
  std::vector<std::byte> record(const Eigen::Vector3d& value_depth, double lsb,
                                DeviceTime stamp) const;
  /// With noise: `bias` walks one sample period at `rate_hz`, then `v` gets it and white noise.
  void perturb(Eigen::Vector3d& v, Eigen::Vector3d& bias, double rate_hz, double random_walk,
               double noise_density);

  RealsenseImuModelConfig config_;
  const Trajectory& trajectory_;
  DeviceSchedule accel_schedule_, gyro_schedule_;
  std::mt19937_64 rng_;
  std::uint64_t accel_index_ = 0, gyro_index_ = 0;
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero(), accel_bias_ = Eigen::Vector3d::Zero();
};

}  // namespace posed::sim
