#pragma once
// A VLP-32C on the moving vehicle: every channel of every firing is a ray cast from the sensor
// pose at that firing's own time (so scans are skewed exactly as on a driving robot), turned into
// the packets the real sensor sends.
//
// Timing (drivers/velodyne/sensor_model.cpp): firings every 55.296 µs of the sensor's clock, one
// per data block, 12 per packet (1507 packets/s); channel c fires floor(c/2)·2.304 µs into the
// firing. The rotor turns at `rpm` on the sensor's clock.
// Geometry: the beam of a channel is the one drivers/velodyne/packet_decoder reconstructs from
// the packet, i.e. azimuth = block azimuth (as sent, 0.01°) + the decoder's interpolated
// rotation − the laser's rot_correction, elevation from the calibration, origin offsets
// included. So decoding a noise-free packet returns the cast point up to the 4 mm distance LSB.
// Physics: range noise (Gaussian), reflectivity from the material and incidence angle,
// detection probability falling with range², darkness and grazing incidence, random dropouts.

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <random>
#include <span>

#include "core/time.hpp"
#include "drivers/velodyne/calibration.hpp"
#include "drivers/velodyne/packet_format.hpp"
#include "tools/sim/clock_model.hpp"
#include "tools/sim/sensor_scene.hpp"

namespace posed::sim {

struct LidarModelConfig {
  /// the lidar in the IMU (base_link) frame
  Eigen::Isometry3d T_base_lidar = Eigen::Isometry3d::Identity();
  /// rotor speed [rpm]
  double rpm = 600.0;
  /// rotor azimuth at device time 0 [deg]
  double azimuth0_deg = 0.0;
  /// 1σ range noise [m]
  double range_noise_m = 0.02;
  /// the sensor's physical range limit [m]
  double max_range_m = 200.0;
  /// a 10 % reflective target at normal incidence is detected half the time at this range [m]
  double range_10pct_m = 80.0;
  /// probability of losing a return for no reason [-]
  double random_dropout = 0.002;
  /// 1σ noise on the reported reflectivity [counts]
  double intensity_noise = 1.5;
  /// false: no range/intensity noise and no probabilistic dropouts (geometry tests)
  bool noise = true;
};

/// What a packet was made from, for tests: per block and channel.
struct LidarPacketTruth {
  /// the noise-free cast point in the sensor frame at its firing time [m]; NaN = no hit
  std::array<std::array<Eigen::Vector3f, 32>, 12> p_lidar_m{};
  /// whether the channel carries a return in the packet
  std::array<std::array<bool, 32>, 12> returned{};
  /// true time of each block's first firing [ns since the simulation start]
  std::array<std::int64_t, 12> firing_true_ns{};
};

class LidarModel {
 public:
  LidarModel(const LidarModelConfig& config, const drivers::velodyne::Calibration& calibration,
             const SensorScene& scene, const ClockModel& clock, std::uint64_t seed);

  /// True time at which the next data packet is complete and sent.
  Duration next_data_send() const;
  /// Writes the next 1206-byte data packet into `out` (size ≥ 1206); fills `truth` if given.
  void emit_data(std::span<std::byte> out, LidarPacketTruth* truth = nullptr);

  /// True time of the next position packet (one per second of the sensor's clock).
  Duration next_position_send() const;
  /// Writes the next 512-byte position packet (GPRMC with the UTC of the sensor's clock).
  void emit_position(std::span<std::byte> out);

  std::uint64_t packets() const { return packet_index_; }
  std::uint64_t rays() const { return rays_; }
  std::uint64_t returns() const { return returns_; }

 private:
  struct Channel {
    double cos_v, sin_v, vert_offset_m, horiz_offset_m, dist_correction_m, rot_cdeg, fraction;
    std::int32_t offset_ns;
  };

  DeviceTime first_firing(std::uint64_t packet) const;

  LidarModelConfig config_;
  SensorScene scene_;
  ClockModel clock_;
  std::mt19937_64 rng_;
  std::array<Channel, 32> channels_{};
  double distance_resolution_m_ = 0.004;
  DeviceTime start_device_;
  std::uint64_t packet_index_ = 0;
  std::uint64_t position_index_ = 0;
  std::uint64_t rays_ = 0, returns_ = 0;
};

}  // namespace posed::sim
