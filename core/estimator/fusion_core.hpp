#pragma once
// The fusion core as the pipeline's fusion stage drives it (DESIGN.md, Data flow): measurements
// go in, states come out. Deterministic and clock-free: the same measurements in the same order
// give the same states, so replays are repeatable. Threads belong to the runner around it
// (daemon/pipeline/fusion_stage), never to the estimator.
//
// Order: the runner hands measurements in stamp order (IMU sample stamp, scan end stamp) when its
// Sources are recordings; live, in arrival order, which differs from stamp order by at most the
// queues' latency — an estimator must tolerate that (e.g. through MeasurementGate).

#include <array>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/estimator/nav_state.hpp"
#include "core/estimator/strapdown.hpp"
#include "core/lidar/scan_motion.hpp"
#include "core/measurements.hpp"

namespace posed {

/// What an estimator reports in rt/posed/status and the exit summary.
/// One image stream's quality in the last frame (seed 002): what the back end weighs it by.
struct StreamQualityFigures {
  bool valid = false;          ///< the stream was assessed
  double gradient_metric = 0;  ///< g, share of edge pixels mapped to [0..1]
  double noise_sigma = 0;      ///< sigma_n [grey]
  double confidence = 0;       ///< omega_min / omega (0..1]
  double omega = 0;            ///< covariance scale of the stream's factors [-]
};

/// What a camera front end (core/vision's visual-thermal front end) did; `mode` names it.
struct CameraFigures {
  std::string_view mode;                 ///< "visible", "thermal" or "fused"; empty: no front end
  std::uint64_t frames = 0;              ///< visible frame events the front end processed [1]
  std::uint64_t frames_unusable = 0;     ///< events the mode could not use (no partner, bad image)
  std::uint64_t frames_without_imu = 0;  ///< events dropped: no IMU around their stamps [1]
  std::uint64_t previous_total = 0;      ///< features carried into frames, summed [1]
  std::uint64_t inliers_total = 0;       ///< of those, tracked and RANSAC inliers, summed [1]
  std::uint64_t extracted_total = 0;     ///< new features detected, summed [1]
  std::uint64_t features_total = 0;      ///< features output, summed [1]
  std::uint64_t depth_total = 0;         ///< of those, with a depth, summed [1]
  /// of those, with the D435i depth image's (where the lidar gave none), summed [1]
  std::uint64_t stereo_depth_total = 0;
  /// frame events given the points of a D435i depth image (the one nearest their stamp) [1]
  std::uint64_t depth_images = 0;
  /// thermal frames identical to the one before (shutter closed for the flat-field correction),
  /// left out [1]
  std::uint64_t thermal_frozen = 0;
  /// tracks dropped for staying put while the camera turned (fixed to the camera), summed [1]
  std::uint64_t static_dropped_total = 0;
  int features = 0;          ///< in the last frame [1]
  int depth_associated = 0;  ///< in the last frame [1]
  int lidar_points = 0;      ///< in the last frame's depth tree [1]
  /// visible, thermal, fused (by vision::FrontendMode order) in the last frame
  std::array<StreamQualityFigures, 3> quality{};
  /// means of confidence over the frames where the stream was assessed (visible, thermal, fused)
  std::array<double, 3> mean_confidence{};
  std::array<std::uint64_t, 3> quality_frames{};  ///< frames each mean is over [1]

  /// seed 001's match success rate over the run: inliers over features carried in [0..1]
  double match_success_rate() const {
    return previous_total > 0
               ? static_cast<double>(inliers_total) / static_cast<double>(previous_total)
               : 0.0;
  }
};

/// One camera stream in the back end (visible, thermal, fused: vision::FrontendMode order): how
/// its frame-to-frame motions entered the window as between factors (seed 002).
struct VisualStreamFigures {
  bool configured = false;    ///< this stream feeds the estimate when its images are good enough
  bool active = false;        ///< its quality gate is open now
  double omega = 0;           ///< covariance scale of its last frame (1 without weighting) [-]
  double confidence = 0;      ///< image-quality confidence of its last frame [0..1]
  double gradient = 0;        ///< gradient metric g of its last frame [0..1]
  std::uint64_t frames = 0;   ///< frames it received [1]
  std::uint64_t factors = 0;  ///< between factors it added to the window [1]
  std::uint64_t keyframe_factors = 0;  ///< of which from a keyframe older than the newest state [1]
  std::uint64_t gated_out = 0;         ///< state intervals skipped while its gate was closed [1]
  /// state intervals it stood by while another stream's gate was open (thermal_standby) [1]
  std::uint64_t standby = 0;
  std::uint64_t no_frames = 0;    ///< intervals without a frame near both states [1]
  std::uint64_t failed = 0;       ///< intervals whose motion could not be estimated [1]
  std::uint64_t implausible = 0;  ///< motions refused: too far from the IMU's prediction [1]
  std::uint64_t left = 0;         ///< times the gate closed (image quality fell) [1]
  std::uint64_t rejoined = 0;     ///< times it opened again [1]
  int inliers = 0;                ///< observations kept in its last motion [1]
  int still = 0;  ///< observations of its last motion left out as not moving with the world [1]
  double reprojection_rms_px = 0;  ///< RMS reprojection error of its last motion [px]
  /// median whitened residual |r| of its factors in the window after the last solve [sigma]
  double residual_median = 0;
  /// covariance scale from its residuals (CameraFactorsConfig::residual_scaling) [-]
  double residual_scale = 1;
  /// its features enter as landmarks (a reprojection factor per observation, counted in
  /// `factors`) instead of between factors; then:
  bool landmarks = false;
  std::uint64_t landmarks_anchored = 0;  ///< landmarks created (a feature with lidar depth) [1]
  std::uint64_t landmarks_still = 0;     ///< dropped as holding still in the image [1]
  std::uint64_t landmarks_gated = 0;     ///< observations too far from the window's estimate [1]
  std::uint64_t landmarks_outliers = 0;  ///< dropped after a solve [1]
  std::uint64_t landmarks_tracked = 0;   ///< landmarks whose anchor is in the window now [1]
};

/// Seed 001's adaptive pose selection: which odometry gave each state its initial value.
struct PoseSelectionFigures {
  std::uint64_t lidar_visual_inertial = 0;  ///< the fused (LCI) position [1]
  std::uint64_t lidar_inertial = 0;         ///< the scan match (LIO) [1]
  std::uint64_t visual_inertial = 0;        ///< the camera motion on the IMU (CIO) [1]
  std::uint64_t imu_only = 0;   ///< neither lidar nor camera to choose from: the IMU prediction [1]
  double last_threshold_m = 0;  ///< S of the last decision [m]
};

/// Which measurements entered the estimate at the last state (bits of Modality).
enum Modality : std::uint8_t {
  kModalityImu = 1,
  kModalityLidar = 2,
  kModalityVisible = 4,
  kModalityThermal = 8,
  kModalityFused = 16,
};
/// e.g. "imu+lidar+visible"
std::string modality_names(std::uint8_t modalities);

struct FusionFigures {
  std::uint64_t scans_used = 0;         ///< scans whose match entered the estimate [1]
  std::uint64_t scans_rejected = 0;     ///< matches refused (too few points, implausible jump) [1]
  std::uint64_t scans_degenerate = 0;   ///< matches with a degenerate direction [1]
  std::uint64_t scans_skipped = 0;      ///< scans before alignment or without IMU coverage [1]
  std::uint64_t reinitialisations = 0;  ///< divergences detected and restarted from [1]
  /// why the window last restarted (a string literal; empty before any)
  const char* last_reinitialisation_reason = "";
  HostTime last_reinitialisation_stamp;  ///< the scan it restarted at
  std::uint64_t keyframes = 0;           ///< scans added to the map as keyframes [1]
  /// translation directions where a scan's weak information was dropped for disagreeing with
  /// the cameras [1]
  std::uint64_t lidar_directions_overruled = 0;
  /// translation directions a scan pinned weakly where the cameras, blind, could not check
  /// them: left to the IMU [1]
  std::uint64_t lidar_directions_left_to_imu = 0;
  /// states held to a wheeled vehicle's motion (estimator.vehicle_motion) [1]
  std::uint64_t vehicle_motion_states = 0;
  int degenerate_directions = 0;                              ///< in the last scan's match [1]
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();  ///< current estimate [rad/s]
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();  ///< current estimate [m/s^2]
  /// the map frame's tilt about its x and y as the window estimates it (zero unless
  /// estimator.estimate_gravity_tilt) [rad]
  Eigen::Vector2d gravity_tilt_rad = Eigen::Vector2d::Zero();
  bool gravity_tilt_estimated = false;
  /// the span of headings driven so far [rad]
  double heading_span_rad = 0.0;
  /// window solves so far, and those with the tilt free [1]
  std::uint64_t window_solves = 0;
  std::uint64_t window_solves_tilt_free = 0;
  /// the camera front end's figures (mode empty without one)
  CameraFigures camera;
  /// the camera streams in the back end (visible, thermal, fused)
  std::array<VisualStreamFigures, 3> visual{};
  PoseSelectionFigures selection;
  /// what entered the estimate at the last state (Modality bits)
  std::uint8_t modalities = 0;
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
  HostTime start_stamp;     ///< the scan's first firing (ScanPoint::offset_ns counts from it)
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
  /// Completes what the core hands to a lane of its own (the camera front end's): call once the
  /// measurements have ended, before reading the final figures.
  virtual void flush() {}
  /// Appends the map and keyframe poses built so far; cores without a map (IMU-only) add
  /// nothing, and so does a core not asked to keep one (LioConfig::keep_map).
  virtual void export_map(MapExport& out) const { (void)out; }
  /// Replaces `points_map_m` with the local map the scans are matched against (map frame [m]);
  /// empty for a core without one.
  virtual void local_map(std::vector<Eigen::Vector3f>& points_map_m) const { points_map_m.clear(); }
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
