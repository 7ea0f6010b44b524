#pragma once
// Runs one scenario: builds the world and drive, puts the rig on it, and emits every sensor's raw
// bytes and the ground truth into a SimSink in host-arrival order.
//
// Time bases (docs/simulator.md):
//   true time t     the simulation's reference, 0 at the start
//   host time       host_epoch + t: the recording's log time (what a recorder on the robot
//                   would stamp on arrival), the base of the ground truth
//   device clocks   per device: offset + drift (ClockModel); the lidar's counts from
//                   2024-06-01T00:00:00Z (GPRMC), the A9's from power-on, the D435i's hardware
//                   clock from power-on (colour and depth: one ASIC stamps both); the thermal
//                   camera has none

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "drivers/imu/a9_protocol.hpp"
#include "drivers/velodyne/calibration.hpp"
#include "tools/sim/depth_camera.hpp"
#include "tools/sim/gbuffer.hpp"
#include "tools/sim/imu_model.hpp"
#include "tools/sim/realsense_imu_model.hpp"
#include "tools/sim/sim_sink.hpp"
#include "tools/sim/thermal_camera.hpp"

namespace posed::sim {

/// The rig being simulated (from config/posed.yaml via cmd_sim; plain structs here).
struct SimRig {
  /// lidar in the IMU (base_link) frame
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();
  /// colour camera (optical: x right, y down, z forward) in the IMU frame
  Eigen::Isometry3d T_imu_cam = Eigen::Isometry3d::Identity();
  /// thermal camera in the colour camera frame
  Eigen::Isometry3d T_cam_thermal = Eigen::Isometry3d::Identity();
  /// the A9: rate, noise densities, mounting
  ImuModelConfig imu;
  /// local gravity [m/s²]
  double gravity_mps2 = 9.805;
  /// lidar rotor speed [rpm]
  double lidar_rpm = 600.0;
  /// the VLP-32C's table; empty = the manual's nominal one
  drivers::velodyne::Calibration lidar_calibration;
  /// colour camera: 640x480 at 15 Hz in M2DGR
  CameraIntrinsics visible;
  double visible_rate_hz = 15.0;
  /// thermal camera: 640x512 at 25 Hz, 8-bit video or 16-bit raw counts
  CameraIntrinsics thermal;
  double thermal_rate_hz = 25.0;
  ThermalFormat thermal_format = ThermalFormat::kY8;
  /// host arrival minus exposure for the clockless thermal camera [s]
  double thermal_latency_s = 0.03;
  /// least host arrival minus exposure midpoint of a colour frame: readout plus USB [s]
  double visible_latency_s = 0.041;
  /// the D435i's depth node: intrinsics, rate, baseline, depth units, working range and error
  /// model (its T_base_depth is ignored: the depth frame is T_imu_cam · T_cam_depth)
  DepthCameraConfig depth;
  /// depth (left IR) imager in the colour camera frame
  Eigen::Isometry3d T_cam_depth = Eigen::Isometry3d::Identity();
  /// the D435i's own IMU: rates, noise (its T_base_rsimu is ignored: the IMU is
  /// T_imu_cam · T_cam_depth · T_depth_rsimu)
  RealsenseImuModelConfig realsense_imu;
  /// the D435i's IMU in the depth frame (depth axes, offset to where the BMI055 sits)
  Eigen::Isometry3d T_depth_rsimu = Eigen::Isometry3d::Identity();
};

struct SimOptions {
  std::string scenario = "room";
  /// simulated time [s]
  double duration_s = 10.0;
  std::uint64_t seed = 1;
  /// another drive through the seed's world (make_scenario(); campus and street_night only)
  std::optional<std::uint64_t> drive_seed;
  bool lidar = true;
  bool imu = true;
  bool visible_camera = true;
  bool thermal_camera = true;
  /// the D435i's depth stream (M2DGR has none, so off unless asked for)
  bool depth_camera = false;
  /// the D435i's IMU (accel and gyro over IIO HID; the A9's backup), off unless asked for
  bool realsense_imu = false;
  /// people and vehicles moving through the world (tools/sim/moving_objects.hpp)
  bool dynamic = false;
  /// false: ideal sensors (no noise, no jitter, no dropouts); geometry stays the same
  bool noise = true;
  /// ground-truth pose rate [Hz]
  double ground_truth_rate_hz = 100.0;
  /// host time at true time 0 (a host that booted 100 s ago) [ns]
  std::int64_t host_epoch_ns = 100'000'000'000;
};

struct SimSummary {
  std::uint64_t lidar_packets = 0, position_packets = 0, imu_frames = 0;
  std::uint64_t visible_frames = 0, thermal_frames = 0, depth_frames = 0, ground_truth_poses = 0;
  /// with SimOptions::dynamic: "N people, M vehicles"
  std::string moving_objects;
  /// D435i IMU records, accel and gyro
  std::uint64_t realsense_accel_records = 0, realsense_gyro_records = 0;
  /// lidar rays cast / returns encoded
  std::uint64_t lidar_rays = 0, lidar_returns = 0;
  /// world size
  std::uint64_t boxes = 0;
  /// loop length of the drive [m]
  double path_length_m = 0;
  /// distance driven [m]
  double distance_m = 0;
  /// wall minus host time to use for the recording (a fixed, seed-independent date) [ns]
  std::int64_t host_to_wall_ns = 0;
};

/// Called now and then with the simulated time done [s]; return false to stop early.
using SimProgress = std::function<bool(double done_s)>;

/// Runs the simulation. false + `error` for a bad scenario/option or a failing sink.
bool run_simulation(const SimRig& rig, const SimOptions& options, SimSink& sink,
                    SimSummary& summary, std::string& error, const SimProgress& progress = {});

/// The wall time the simulated recording claims to start at: 2024-06-01T12:00:00Z [ns].
inline constexpr std::int64_t kSimWallStartNs = 1'717'243'200'000'000'000;
/// The Metadata record `posectl sim` writes: scenario, seed, duration_s, host_epoch_ns,
/// gravity_mps2, noise, and drive_seed when one was given (make_scenario() rebuilds the world
/// and drive from them); with smoke (the `smoke` scenario) also visible_degraded_from_s,
/// visible_degraded_to_s, smoke_dense_from_s, smoke_dense_to_s [s, true time since the start]
/// and smoke_extinction_per_m (docs/simulator.md).
inline constexpr std::string_view kSimMetadataName = "posed.sim";

}  // namespace posed::sim
