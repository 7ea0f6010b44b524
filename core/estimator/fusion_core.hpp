#pragma once
// The fusion core as the pipeline's fusion stage drives it (DESIGN.md, Data flow): measurements
// go in, states come out. Deterministic and clock-free: the same measurements in the same order
// give the same states, so replays are repeatable. Threads belong to the runner around it
// (daemon/pipeline/fusion_stage), never to the estimator.
//
// Order: the runner hands measurements in stamp order (IMU sample stamp, scan end stamp) when its
// Sources are recordings; live, in arrival order, which differs from stamp order by at most the
// queues' latency — an estimator must tolerate that (e.g. through MeasurementGate).

#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "core/estimator/nav_state.hpp"
#include "core/estimator/strapdown.hpp"
#include "core/lidar/scan_motion.hpp"
#include "core/measurements.hpp"

namespace posed {

/// What an estimator reports in rt/posed/status and the exit summary.
struct FusionFigures {
  std::uint64_t scans_used = 0;         ///< scans whose match entered the estimate [1]
  std::uint64_t scans_rejected = 0;     ///< matches refused (too few points, implausible jump) [1]
  std::uint64_t scans_degenerate = 0;   ///< matches with a degenerate direction [1]
  std::uint64_t scans_skipped = 0;      ///< scans before alignment or without IMU coverage [1]
  std::uint64_t reinitialisations = 0;  ///< divergences detected and restarted from [1]
  std::uint64_t keyframes = 0;          ///< scans added to the map as keyframes [1]
  int degenerate_directions = 0;        ///< in the last scan's match [1]
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();  ///< current estimate [rad/s]
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();  ///< current estimate [m/s^2]
};

/// The map an estimator built over a run, for export at its end (posed --save-map).
struct MapExport {
  struct Keyframe {
    HostTime stamp;                ///< the keyframe scan's end
    Eigen::Isometry3d T_map_base;  ///< base_link (IMU frame) in the map frame
  };
  std::vector<Eigen::Vector3f> points_map_m;  ///< map frame [m]
  double voxel_m = 0;                         ///< resolution the points were merged at [m]
  std::vector<Keyframe> keyframes;
};

/// The newest scan a core matched, deskewed to its end, and where it was: what a camera front
/// end needs for lidar depth. The points stay valid until the core's next add_scan().
struct MatchedScan {
  std::uint64_t index = 0;  ///< counts matched scans from 1: a new value is a new scan [1]
  HostTime stamp;           ///< the scan's end, where the points are deskewed to
  Eigen::Isometry3d T_map_lidar = Eigen::Isometry3d::Identity();
  std::span<const lidar::ScanPoint> points_lidar;  ///< in the lidar frame at `stamp`
};

class FusionCore {
 public:
  virtual ~FusionCore() = default;
  /// One IMU sample; appends the states it produced (possibly none) to `states`.
  virtual void add_imu(const ImuSample& sample, std::vector<NavState>& states) = 0;
  /// One lidar scan; its pool buffer returns when the core drops the scan. Appends states.
  virtual void add_scan(LidarScan scan, std::vector<NavState>& states) = 0;
  /// One camera frame (stamp on the host clock); its pool buffer returns when the core drops
  /// the image. A core without a visual front end drops it at once.
  virtual void add_image(CameraStream stream, Image image, std::vector<NavState>& states) {
    (void)stream;
    (void)image;
    (void)states;
  }
  virtual EstimatorMode mode() const = 0;
  /// one line for the summary and logs, e.g. "strapdown (IMU-only dead reckoning ...)"
  virtual std::string_view description() const = 0;
  virtual FusionFigures figures() const = 0;
  /// Appends the map and keyframe poses built so far; cores without a map (IMU-only) add
  /// nothing, and so does a core not asked to keep one (LioConfig::keep_map).
  virtual void export_map(MapExport& out) const { (void)out; }
  /// The newest matched scan; false for a core without a lidar or before its first match.
  virtual bool latest_matched_scan(MatchedScan& out) const {
    (void)out;
    return false;
  }
};

/// IMU-only dead reckoning (Strapdown): the core for configurations without aiding sensors.
/// Scans are accepted and released unused.
std::unique_ptr<FusionCore> make_strapdown_core(const StrapdownConfig& config);

}  // namespace posed
