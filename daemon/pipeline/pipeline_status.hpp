#pragma once
// The pipeline's figures for rt/posed/status, the systemd STATUS= line and the exit summary.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/estimator/fusion_core.hpp"
#include "core/estimator/nav_state.hpp"
#include "core/time.hpp"

namespace posed::pipeline {

/// The mapping stage's figures, for rt/diagnostics and the status line.
struct MappingStatus {
  bool localising = false;  ///< on a prior map (posed --map), not closing loops
  /// localising: "aligning", "localised" or "lost"; closing loops: "mapping"
  std::string state;
  std::uint64_t keyframes = 0;      ///< closing loops: keyframes in the graph [1]
  std::uint64_t loops = 0;          ///< closing loops: accepted [1]
  std::uint64_t fixes = 0;          ///< localising: verified registrations onto the map [1]
  double correction_m = 0;          ///< map -> odom's translation [m]
  std::uint64_t scans_skipped = 0;  ///< live: scans the full queue kept from the stage [1]
};

/// Per-stream figures.
struct StreamStatus {
  std::string name;
  double rate_hz = 0;          ///< decoded per second between status messages (publisher only)
  std::uint64_t received = 0;  ///< chunks read from the Source
  /// chunks the Source refused before decoding: datagrams from another sender than the
  /// configured sensor, oversized datagrams
  std::uint64_t refused = 0;
  std::uint64_t decoded = 0;    ///< measurements decoded
  std::uint64_t dropped = 0;    ///< measurements dropped by the queue policy
  std::uint64_t malformed = 0;  ///< frames rejected by the decoder (CRC, truncation, unknown)
  /// of `malformed`, those no decoder was there for (an unknown wire format, a CAN IMU without
  /// imu.can_mapping): a configuration problem rather than damaged data
  std::uint64_t undecodable = 0;
  std::int64_t clock_offset_ns = 0;  ///< host minus device time [ns]
  double clock_drift_ppm = 0;        ///< device clock rate error [ppm]
  double clock_jitter_ns = 0;        ///< spread of arrival delays [ns]
  double clock_uncertainty_ns = 0;   ///< 1-sigma of the mapped stamps [ns]
  std::string clock_state;           ///< converging | locked | lost
  std::string health;                ///< ok | no_data | degraded | device_lost
};

struct PipelineStatus {
  HostTime stamp;
  EstimatorMode mode = EstimatorMode::kAligning;
  std::vector<StreamStatus> streams;
  std::uint64_t lidar_scans = 0;   ///< scans assembled
  std::uint64_t lidar_points = 0;  ///< points in those scans
  /// scans left out as stale: open when the lidar fell silent (LidarScanCounters::cut_by_silence)
  std::uint64_t lidar_scans_cut_by_silence = 0;
  /// scans left out as stamped implausibly far from their arrival (LidarScanCounters::implausible)
  std::uint64_t lidar_scans_implausible = 0;
  std::uint64_t lidar_scans_fused = 0;  ///< scans the fusion core received
  /// camera frames the fusion core received, by CameraStream (visible, thermal)
  std::uint64_t camera_frames_fused[3] = {0, 0, 0};
  /// the estimator's own figures (scans used, degeneracy, biases, re-initialisations)
  FusionFigures estimator;
  /// which IMU the estimate runs on: "a9", or "d435i" while it stands in for a silent A9; empty
  /// without the D435i's IMU (realsense_imu.failover)
  std::string imu_in_use;
  std::uint64_t imu_failovers = 0;    ///< times the D435i's IMU took over
  std::uint64_t imu_backup_used = 0;  ///< its samples the estimate used
  std::uint64_t states = 0;           ///< states produced by the fusion core
  std::uint64_t states_dropped = 0;   ///< states dropped between fusion and publisher
  /// the mapping stage (none without one)
  std::optional<MappingStatus> mapping;
};

}  // namespace posed::pipeline
