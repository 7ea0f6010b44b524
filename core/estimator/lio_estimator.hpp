#pragma once
// The lidar-inertial estimator (seed 000 §2.3, seed 001; LIO-SAM's loosely coupled factor graph
// on a fixed lag): a FusionCore fed IMU samples and VLP-32C scans in stamp order.
//
//   start-up   the rig stands still: static alignment (roll, pitch, gyro bias); the map frame is
//              the IMU at that moment, yaw 0. A rig already moving is aligned from its mean
//              rotation-compensated specific force after `moving_alignment_after`, starting
//              with wide priors on tilt, velocity and gyro bias that the window narrows.
//   per scan   released by the MeasurementGate once the IMU covers its last firing; the IMU is
//              preintegrated from the previous state to the scan's end; the prediction deskews the
//              scan and seeds scan-to-map; the window gets the state with its preintegration and
//              lidar pose factors and is optimised; the scan joins the map at the optimised pose;
//              the optimised state is published (rt/posed/pose).
//   per IMU    propagation from the newest optimised state (rt/posed/odom, low latency).
//   divergence speed, bias or pose-jump limits exceeded: the window restarts from the last good
//              lidar pose (counted, mode kReinitialising); the map is kept.
//
// Deterministic, no threads, no clocks (core/ rules).

#include <array>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "core/estimator/fusion_core.hpp"
#include "core/estimator/pose_selection.hpp"
#include "core/estimator/sliding_window.hpp"
#include "core/estimator/window_aiding.hpp"
#include "core/imu/moving_alignment.hpp"
#include "core/imu/preintegration.hpp"
#include "core/imu/static_alignment.hpp"
#include "core/lidar/lidar_odometry.hpp"
#include "core/lidar/map_cloud.hpp"
#include "core/sync/imu_buffer.hpp"
#include "core/sync/measurement_gate.hpp"

namespace posed::estimator {

struct LioConfig {
  double gravity_mps2 = 9.805;
  imu::ImuNoise noise;
  /// the backup IMU's (ImuSample::from_backup_imu); none: it is weighed as the primary
  std::optional<imu::ImuNoise> backup_noise;
  imu::StaticAlignmentConfig alignment;
  /// without a still window by then, align while moving (MovingAlignment) [ns]
  Duration moving_alignment_after = Duration::from_s(3);
  /// the lidar in the IMU (base_link) frame
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();
  lidar::LidarOdometryConfig lidar;
  SlidingWindowConfig window;  ///< gravity and T_imu_lidar are copied in from above
  /// A wheeled or tracked vehicle's motion (VehicleMotionFactor): the point `vehicle_centre_m`
  /// of base_link moves along base_link's x only, to these sigmas. kWhereBlind: only on states
  /// where nothing else pins the speed along the lidar's weak direction (the lidar weak, no
  /// camera motion for the state) and the vehicle turns at `vehicle_min_yaw_rate_radps` or more:
  /// where its heading leaves the axis, the sideways speed the lidar pins gives the speed along
  /// it. Off for a handheld or legged rig.
  enum class VehicleMotion : std::uint8_t { kOff, kEveryState, kWhereBlind };
  VehicleMotion vehicle_motion = VehicleMotion::kOff;
  double vehicle_min_yaw_rate_radps = 0;                       ///< kWhereBlind [rad/s]
  double vehicle_lateral_sigma_mps = 0.05;                     ///< [m/s]
  double vehicle_vertical_sigma_mps = 0.05;                    ///< [m/s]
  Eigen::Vector3d vehicle_centre_m = Eigen::Vector3d::Zero();  ///< in base_link [m]
  // Divergence limits: beyond any of them the estimate is not trusted.
  double max_speed_mps = 40.0;       ///< [m/s]
  double max_gyro_bias_radps = 0.3;  ///< [rad/s]
  double max_accel_bias_mps2 = 2.0;  ///< [m/s^2]
  /// a scan match this far from the IMU prediction is refused rather than believed [m]
  double max_match_jump_m = 1.0;
  double max_match_jump_rad = 0.2;  ///< [rad]
  /// While the aiding (the cameras) is active, a scan is degenerate along a translation it pins
  /// with fewer point constraints than this, and says nothing along it: in a roadway whose pipes
  /// and trays run its whole length the lidar "pins" the axis through plane fits tilted by the
  /// fittings, a confidence the cameras then have to fight (lidar.matcher's own threshold and
  /// information scale apply otherwise) [1], [-]
  double aided_degeneracy_translation_threshold = 10;
  double aided_degenerate_information_scale = 0;
  /// A scan's translation information below this along a direction (200 point constraints at
  /// the matcher's 5 cm residual sigma) is checked against the cameras' motion for the same
  /// interval; where they disagree beyond `aided_consistency_sigma` the scan says nothing along
  /// it (reconcile()) [1/m²], [sigma]
  double aided_trusted_information = 8e4;
  double aided_consistency_sigma = 3.0;
  /// reconcile() only within this time after a scan with a degenerate direction [s]
  double aided_suspect_window_s = 5.0;
  /// Where reconcile() would check the scan but the cameras gave no motion for the interval
  /// (their gates closed: smoke, darkness; or every pair failed), and the scan pins one
  /// translation with less than this share of the information of its best-pinned one while the
  /// other two are above it (a tube's signature), that translation says nothing and the IMU
  /// carries it. In a roadway the scans hold the axis: on smoke seed 36 lidar and IMU
  /// alone stood still along it (0.00-0.06 m/s) while the robot drove 1 m/s, with the axis's
  /// information 0.3-0.45 of the lateral's on scans not flagged degenerate; the lidar cannot be
  /// checked there, and a few seconds of the IMU drift less than a lidar that says "still".
  /// 0: off [-]
  double aided_blind_weak_ratio = 0.5;
  /// The lidar is settled once every scan for this long has pinned every direction (none
  /// degenerate or rejected, the window not restarted): the aiding then weighs itself as beside a
  /// lidar that has fixed the speed and biases (WindowAiding::set_lidar_state) [s]
  double aided_settled_after_s = 5.0;
  /// seed 001's adaptive pose selection of each state's initial value (pose_selection.hpp); off:
  /// the IMU prediction
  bool pose_selection = true;
  /// keep every keyframe's points in a whole-run map for export_map(); off on a robot that
  /// never exports, since it grows with the area explored
  bool keep_map = false;
  double map_voxel_m = 0.1;  ///< resolution of that map [m]
};

/// The steps of one scan, for profilers (`posectl bench lio`): the estimator calls the probe at
/// each step's start and end; it reads no clock itself.
enum class LioStep : std::uint8_t {
  kPredict,    ///< IMU preintegration to the scan's end, deskew motion
  kDeskew,     ///< points into the frame at the scan's end
  kFeatures,   ///< range image, ground, edges and planes
  kMatch,      ///< scan-to-map
  kWindow,     ///< fixed-lag window: add, solve, marginalise
  kMapUpdate,  ///< the scan into the map, covariance, re-propagation
};
inline constexpr std::array<std::string_view, 6> kLioStepNames = {
    "predict", "deskew", "features", "match", "window", "map_update"};

class LioStepProbe {
 public:
  virtual ~LioStepProbe() = default;
  virtual void begin(LioStep step) = 0;
  virtual void end(LioStep step) = 0;
};

class LioEstimator final : public FusionCore {
 public:
  explicit LioEstimator(const LioConfig& config);
  /// Optional: called around every step of every scan (null: none).
  void set_probe(LioStepProbe* probe) { probe_ = probe; }
  /// Optional: further relative-motion factors for every new state (the cameras; null: none).
  void set_aiding(WindowAiding* aiding) { aiding_ = aiding; }
  /// Optional: helper threads for the lidar front end's per-point work (null: the caller's
  /// thread does all of it). The estimate is bit-identical either way (core/work_splitter.hpp).
  void set_splitter(WorkSplitter* splitter) { lidar_.set_splitter(splitter); }

  void add_imu(const ImuSample& sample, std::vector<NavState>& states) override;
  void add_scan(LidarScan scan, std::vector<NavState>& states) override;
  EstimatorMode mode() const override { return mode_; }
  std::string_view description() const override {
    return "lidar-inertial (scan-to-map with degeneracy handling, IMU preintegration, fixed-lag "
           "window)";
  }
  FusionFigures figures() const override;
  void export_map(MapExport& out) const override;
  bool latest_matched_scan(MatchedScan& out) const override;
  void local_map(std::vector<Eigen::Vector3f>& points_map_m) const override;

  const lidar::LidarOdometry& lidar_odometry() const { return lidar_; }
  const SlidingWindow& window() const { return window_; }

 private:
  struct Integrated {
    imu::Preintegration pre;
    bool covered = false;  ///< the IMU reached both ends
  };
  void release_scans(std::vector<NavState>& states);
  void process_scan(const Bundle<LidarScan>& bundle, std::vector<NavState>& states);
  /// The new state at the scan's end joins the window with its IMU, lidar and aiding factors,
  /// from the initial value the pose selection chose; the window is solved.
  void add_to_window(const imu::ImuState& predicted, const imu::Preintegration& pre,
                     const lidar::ScanMatchResult& match);
  /// The body's angular rate at the newest IMU sample, less `state`'s gyro bias [rad/s].
  Eigen::Vector3d body_rate(const imu::ImuState& state) const;
  /// Whether `state`, about to join the window, takes a VehicleMotionFactor (config's
  /// vehicle_motion); needs this scan's motions_ and lidar_suspect_.
  bool vehicle_motion_applies(const imu::ImuState& state) const;
  /// Drops the scan's information along weakly pinned translations where it disagrees with the
  /// aiding's motions for this interval (see aided_trusted_information).
  void reconcile(LidarPose& lidar);
  /// The scan's one weakly pinned translation under two firm ones, unchecked while the cameras
  /// are blind, says nothing (aided_blind_weak_ratio).
  void leave_weak_directions_to_imu(LidarPose& lidar);
  /// Seed 001's choice among the IMU prediction, the scan match and the aiding's motions.
  imu::ImuState initial_value(const imu::ImuState& predicted, const imu::Preintegration& pre,
                              const lidar::ScanMatchResult& match);
  /// Preintegrates the held IMU from `from` (its stamp and biases) to `t`, filling the deskew
  /// motion of the lidar over [from.stamp, t] when `motion` is given.
  Integrated integrate(const imu::ImuState& from, HostTime t, lidar::ScanMotion* motion);
  void reanchor_propagation(const imu::ImuState& state);
  NavState to_nav_state(const imu::ImuState& s, const Eigen::Vector3d& w_body, bool optimised,
                        const Eigen::Matrix<double, 6, 6>& cov_tangent) const;
  /// Restarts the window at `at` (pose) with `v_map_mps` and the start-up biases; counted.
  /// `reason`: a string literal for the figures (and so the log).
  void reinitialise(const imu::ImuState& at, const Eigen::Vector3d& v_map_mps, const char* reason);
  /// Why `s` diverged, or null if it did not.
  const char* divergence(const imu::ImuState& s) const;
  /// A match close enough to the prediction to be believed.
  bool plausible(const lidar::ScanMatchResult& match, const Eigen::Isometry3d& T_predicted) const;
  /// The lidar's own prediction for `t`: the last two matched poses' twist held (no IMU).
  struct LidarPrediction {
    Eigen::Isometry3d T_map_lidar;
    Eigen::Vector3d v_map_mps;
    lidar::ScanMotion motion;  ///< over [last match, t], for deskew
  };
  std::optional<LidarPrediction> constant_velocity(HostTime t) const;
  Eigen::Vector3d lidar_velocity_or_zero(HostTime t) const;
  /// The IMU state (pose only) whose lidar is at T_map_lidar.
  imu::ImuState imu_state_at(const Eigen::Isometry3d& T_map_lidar, HostTime t) const;

  LioConfig config_;
  imu::StaticAlignment alignment_;
  imu::MovingAlignment moving_alignment_;
  std::optional<HostTime> first_imu_;
  std::optional<imu::StaticAlignmentResult> aligned_;
  bool aligned_moving_ = false;  ///< velocity and gyro bias unknown at start
  ImuBuffer imu_;
  MeasurementGate<LidarScan> gate_;
  std::vector<ImuSample> bundle_imu_;
  std::vector<ImuSample> scratch_;
  lidar::LidarOdometry lidar_;
  lidar::MapCloud map_cloud_;  ///< whole-run map, only when config_.keep_map
  std::vector<MapExport::Keyframe> map_keyframes_;
  std::uint64_t matched_scans_ = 0;  ///< scans whose match was used; indexes MatchedScan [1]
  lidar::ScanMotion motion_;
  SlidingWindow window_;
  /// the state published poses are propagated from (the newest optimised one)
  std::optional<imu::ImuState> anchor_;
  Eigen::Matrix<double, 6, 6> anchor_cov_ = Eigen::Matrix<double, 6, 6>::Identity() * 1e-6;
  /// IMU propagation for odom: from the anchor through every sample since
  imu::ImuState propagated_;
  std::optional<ImuSample> propagated_last_;
  bool first_state_emitted_ = false;
  /// the last two matched lidar poses (stamp, T_map_lidar), oldest first
  std::array<std::optional<std::pair<HostTime, Eigen::Isometry3d>>, 2> matched_;
  HostTime matched_start_;  ///< start stamp of the scan in matched_[1]
  EstimatorMode mode_ = EstimatorMode::kAligning;
  FusionFigures figures_;
  std::uint64_t sequence_ = 0;
  LioStepProbe* probe_ = nullptr;
  WindowAiding* aiding_ = nullptr;
  std::vector<RelativeMotion> motions_;            // this scan's, from the aiding
  std::vector<std::uint64_t> from_ids_;            // the window ids their motions start from
  std::optional<HostTime> last_degenerate_stamp_;  // of the last scan with a degenerate direction
  bool lidar_suspect_ = false;  // one was found within aided_suspect_window_s (reconcile())
  std::optional<HostTime> strong_since_;  // every scan since pinned every direction
  bool lidar_settled_ = false;            // for aided_settled_after_s
  bool aided_degeneracy_ = false;         // the lidar's degeneracy is set for an active aiding
  void begin(LioStep s) {
    if (probe_ != nullptr) probe_->begin(s);
  }
  void end(LioStep s) {
    if (probe_ != nullptr) probe_->end(s);
  }
};

}  // namespace posed::estimator
