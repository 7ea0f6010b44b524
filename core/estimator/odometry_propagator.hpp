#pragma once
// IMU-rate odometry that never waits for the back end (LIO-SAM's imuPreintegration node, in
// spirit): each IMU sample is integrated onto the newest optimised state the back end handed
// over (an anchor). When a new anchor lands it is older than the odometry already published (it
// is at a scan's end, and the scan took time): the held IMU is integrated again from it, and the
// difference to what was published — the correction — is blended out over `blend_s` so no output
// jumps: each step moves by at most correction x (sample period / blend_s) beyond the IMU's own
// motion. Corrections too large to be a refinement (a re-initialisation) are applied at once.
//
// Deterministic, no threads, no clocks (core/ rules): the daemon runs it on the IMU stage's
// thread (daemon/pipeline/odometry_path.hpp) and decides when an anchor is handed in.

#include <cstdint>
#include <optional>
#include <vector>

#include "core/estimator/nav_state.hpp"
#include "core/imu/preintegration.hpp"
#include "core/measurements.hpp"
#include "core/sync/imu_buffer.hpp"

namespace posed::estimator {

struct OdometryPropagatorConfig {
  double gravity_mps2 = 9.805;
  double accel_noise_density = 0;  ///< for the covariance's growth [m/s^2/sqrt(Hz)]
  double gyro_noise_density = 0;   ///< [rad/s/sqrt(Hz)]
  /// the backup IMU's, for its samples (ImuSample::from_backup_imu); 0: as the primary's
  double backup_accel_noise_density = 0;  ///< [m/s^2/sqrt(Hz)]
  double backup_gyro_noise_density = 0;   ///< [rad/s/sqrt(Hz)]
  /// a correction is spread linearly over this long; 0 applies it at once (snap) [s]
  double blend_s = 0.1;
  /// corrections beyond either of these are applied at once [m], [rad]
  double snap_m = 1.0;
  double snap_rad = 0.2;
  /// IMU held for integrating again from a late anchor [samples]; 2 s at 400 Hz by default
  std::size_t history_samples = 800;
};

struct OdometryFigures {
  std::uint64_t anchors = 0;  ///< anchors handed in [1]
  std::uint64_t snaps = 0;    ///< corrections applied at once (too large to blend) [1]
  /// anchors older than the IMU held, integrated from the oldest sample instead [1]
  std::uint64_t stale_anchors = 0;
  double last_correction_m = 0;    ///< position correction of the last anchor [m]
  double last_correction_rad = 0;  ///< rotation correction of the last anchor [rad]
  double max_correction_m = 0;     ///< largest position correction so far [m]
};

class OdometryPropagator {
 public:
  explicit OdometryPropagator(const OdometryPropagatorConfig& config);

  /// A state the back end optimised (or its aligned start), with its biases. Anchors older
  /// than the current one are ignored.
  void set_anchor(const NavState& anchor);
  /// Integrates one IMU sample; true with `out` set once an anchor exists and the sample is
  /// newer than the last one integrated.
  bool add_imu(const ImuSample& sample, NavState& out);

  bool has_anchor() const { return anchor_.has_value(); }
  const OdometryFigures& figures() const { return figures_; }

 private:
  /// One midpoint step from `from` to `to` with the anchor's biases.
  imu::ImuState step(const imu::ImuState& state, const ImuSample& from, const ImuSample& to) const;
  NavState output(const ImuSample& sample);

  OdometryPropagatorConfig config_;
  ImuBuffer history_;
  std::vector<ImuSample> scratch_;
  std::optional<NavState> anchor_;
  /// the anchor's gravity in map (NavState::gravity_map_mps2; zero: the config's)
  Eigen::Vector3d gravity_map_mps2_ = Eigen::Vector3d::Zero();
  /// the anchor carried forward through every sample since (without the blend)
  imu::ImuState propagated_;
  std::optional<ImuSample> last_;
  /// the last output, which the next anchor's correction is measured against
  std::optional<NavState> published_;
  /// the correction still being blended out: added to the propagation, shrinking to zero
  Eigen::Vector3d offset_p_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d offset_rot_rad_ = Eigen::Vector3d::Zero();  ///< left, map-fixed axes
  HostTime blend_start_;
  std::uint64_t sequence_ = 0;
  OdometryFigures figures_;
};

}  // namespace posed::estimator
