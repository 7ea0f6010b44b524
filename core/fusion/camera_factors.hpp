#pragma once
// The cameras in the estimate (issue 17): each camera stream's frame-to-frame motion, with metric
// scale from the features' lidar depth, enters the lidar-inertial window as a relative-pose
// ("between") factor between consecutive states, weighed by the stream's image quality (seed 002:
// Σ = ω Σ_base, ω from the gradient metric g and the noise σn), and gated out while the images
// are too poor to trust.
//
// Why loosely coupled between factors rather than reprojection factors with inverse depths
// (VINS-Mono, LVI-SAM's VIS): the front end already gives every feature its lidar depth, so two
// frames pin the camera's motion on their own (frame_motion.hpp) and a factor of 6 residuals per
// state carries it; the window stays at 15 coordinates per state and its cost per scan grows by
// microseconds, where hundreds of reprojection factors and landmark blocks would cost tens of
// milliseconds on a 2-core robot. The price: a feature seen over many states constrains each
// pair of states, not the whole span at once (keyframes lengthen the pairs). Seed 002 makes the
// same choice for visible and thermal odometry; seed 001's point residuals are the tightly
// coupled alternative.
//
// Timing. States sit at scan ends (10 Hz), frames at 15 Hz (visible) or the visible events
// (thermal mode runs on them too). A factor ties the new state j to a state k of the window: the
// previous state, or where the lidar is weak a keyframe a few states back (keyframe_states). It
// uses the last frame at or before each state's stamp; the short intervals between a frame and
// its state are bridged with the window's own motion, interpolated between the neighbouring
// states (linear in position, SLERP in rotation: seed 002's interpolation), which over tens of
// milliseconds is good to a millimetre.
// Frames' stamps are ClockSync's (the D435i's hardware clock; the thermal camera's arrival minus
// its configured latency). The camera-IMU extrinsic comes from the configuration.
//
// Geometry. The visible and fused streams are in the visible camera's frame. The thermal stream
// tracks the thermal image registered to the visible camera's pixel grid at infinity: its
// features are rays of a camera at the thermal camera's origin with the visible camera's axes
// (the front end gives them lidar depth in that frame), so its T_imu_sensor is T_imu_cam
// translated by T_cam_thermal's translation.
//
// Pure and deterministic: it runs on the fusion thread, called in the order of the measurements.

#include <Eigen/Geometry>
#include <array>
#include <deque>
#include <optional>
#include <vector>

#include "core/estimator/fusion_core.hpp"
#include "core/estimator/window_aiding.hpp"
#include "core/fusion/frame_motion.hpp"
#include "core/fusion/visual_landmarks.hpp"
#include "core/vision/frontend_frame.hpp"

namespace posed::fusion {

/// How a camera stream enters the window: frame-pair motions as between factors, or its
/// features as landmarks with a reprojection factor per observation (visual_landmarks.hpp).
enum class CameraCoupling : std::uint8_t {
  kBetween,    ///< a between factor per stream and state
  kLandmarks,  ///< landmarks only
  kBoth,       ///< a between factor per stream and state, and landmarks
};

struct CameraFactorsConfig {
  CameraCoupling coupling = CameraCoupling::kBetween;
  VisualLandmarksConfig landmarks;  ///< with kLandmarks; focal_px is set from focal_px below
  /// which streams feed the estimate (visible, thermal, fused; vision::FrontendMode order)
  std::array<bool, 3> streams{};
  /// each stream's camera in base_link (see the header comment for the thermal one)
  std::array<Eigen::Isometry3d, 3> T_imu_sensor{
      Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()};
  /// focal length of the grid the features are in (the visible camera's) [px]
  double focal_px = 600;
  /// Σ_base: feature position noise of a frame-to-frame motion [px]
  double pixel_sigma_px = 1.0;
  FrameMotionConfig motion;  ///< pixel_sigma and fix_rotation are set from the above and below
  /// the cameras measure translation only, at the rotation the window (gyro, lidar) gives:
  /// see frame_motion.hpp's fix_rotation
  bool translation_only = true;
  /// features tracked over fewer frames are left out: a young track is often a corner of noise
  /// that KLT has not yet lost (on the simulated corridor, tracks of 1-2 frames miss the true
  /// motion by 3 px at the median, tracks of 5 or more by 0.35 px) [1]
  std::uint32_t min_track_length = 4;
  /// fewer observations (features with depth, counted in each frame they have it) in a frame
  /// pair: no motion [1]
  int min_observations = 8;
  /// features further than this from where the window's prediction puts them are left out of a
  /// frame pair's motion (frame_motion.hpp's guess_gate) [px]
  double guess_gate_px = 3.0;
  /// the same gate where the lidar has recently been weak (set_lidar_state): there the window's
  /// speed along the lidar's blind direction is only as good as the cameras made it, and a guess
  /// a quarter off moves a near feature's prediction by more than 3 px; what is left inside a
  /// tight gate are the distant features, which agree with any speed and confirm the guess [px]
  double weak_lidar_guess_gate_px = 6.0;
  /// the thermal and fused streams' gates never fall back to all observations
  /// (FrameMotionConfig::gate_falls_back): their fixed pattern can be the majority
  bool thermal_gate_strict = true;
  /// with a visible (or fused) stream configured, the thermal stream's factors enter only while
  /// that stream's gate is closed (smoke, darkness, a covered lens). On the simulator the
  /// thermal stream's motions are poorer than the visible camera's wherever both see (its
  /// corners are few and partly its own fixed pattern), and as an equal second stream it made
  /// the corridor and tunnel worse; where the visible camera is blind it is all there is
  /// (docs/estimator.md, "The thermal camera on standby"). Its front end runs throughout, so
  /// its tracks and its fixed-pattern correction are ready when it is needed.
  bool thermal_standby = false;
  /// Σ = ω Σ_base with ω from the image quality (seed 002); false: ω = 1
  bool quality_weighting = true;
  /// a stream whose confidence stays below this for `leave_frames` frames stops contributing,
  /// and comes back once it is at or above `rejoin_confidence` for `rejoin_frames` frames [0..1]
  double min_confidence = 0.05;
  double rejoin_confidence = 0.08;
  /// and the same with the gradient metric g alone: smoke or darkness takes an image's edges
  /// (g near 0) before its noise estimate moves ω [0..1]
  double min_gradient = 0.02;
  double rejoin_gradient = 0.04;
  int leave_frames = 3;
  int rejoin_frames = 5;
  /// a state uses the last frame at most this much before its stamp [ns]
  Duration max_frame_age = Duration::from_ms(80);
  /// 1-sigma floors added to each factor's covariance: a frame pair's features are not
  /// independent (tracking errors, depth association, time offsets) [rad], [m]
  double floor_rotation_rad = 0.001;
  double floor_translation_m = 0.002;
  /// the translation floor where the lidar is strong and settled (set_lidar_state: not
  /// weak, settled: no degenerate or rejected scan for aided_settled_after_s): there a
  /// scan pins the motion to millimetres and a frame pair's errors only add noise. 30 mm brings
  /// the mine, room and street_night within about a millimetre of the lidar alone (2 mm leaves
  /// them up to 8 mm worse); applied from the first scan on, it cost the tunnel the speed the
  /// cameras measure before it (seed 4, 30 s: 0.37 m against 0.09 m), which the settling time
  /// keeps. But over 10-minute campus drives the cameras take out some of the lidar's slow drift
  /// even where it is strong, and 30 mm cost one seed of five 3.3 m, so the default stays 2 mm
  /// (docs/estimator.md) [m]
  double strong_lidar_floor_translation_m = 0.002;
  /// Huber threshold of the factors in the window [sigma]
  double huber_sigma = 3.0;
  /// scale each stream's covariance by how far its factors sit from the solution compared with
  /// the best stream's (their median whitened residuals, squared; a variance component
  /// estimate between the cameras). Image quality says how sharp a stream's features are, not
  /// whether they are where the stream thinks (a thermal image whose fixed pattern or lens edge
  /// holds still). Against the lidar it would blame the wrong sensor where the lidar aliases.
  bool residual_scaling = true;
  double residual_scale_max = 1000;  ///< [-]
  /// Motions start from a keyframe state and end at each new state, for up to this many states
  /// before the newest state becomes the next keyframe (1: consecutive states only). Over a
  /// longer baseline the features' flow grows while their noise does not, and the states'
  /// positions hang from one frame instead of a chain of frame pairs whose errors add up: on the
  /// simulated corridor a frame pair's motion along the axis is good to 4 cm at 1 m/s, a random
  /// walk over the hundreds of pairs a minute's drive takes. The keyframe must stay in the
  /// window, so this is at most the window's size less one [states]. Only where the lidar has
  /// recently been weak (set_lidar_state): the rotation is the window's, and over a longer
  /// baseline its error moves distant features further; where the lidar pins every direction,
  /// consecutive pairs measured better (street_night seed 11: 0.034 m against 0.047 m).
  int keyframe_states = 5;
  /// a motion further than this from the IMU's prediction over one interval is refused [m], [rad]
  double max_disagreement_m = 0.3;
  double max_disagreement_rad = 0.1;
};

class CameraFactors final : public estimator::WindowAiding {
 public:
  explicit CameraFactors(const CameraFactorsConfig& config);

  /// A frame of `stream` the front end processed: its features and image quality.
  void add_frame(vision::FrontendMode stream, const vision::FrontendFrame& frame);

  void relative_motions(const estimator::SlidingWindow& window, const imu::ImuState& next,
                        std::vector<estimator::RelativeMotion>& out) override;
  std::uint8_t add_factors(estimator::SlidingWindow& window) override;
  void after_solve(const estimator::SlidingWindow& window) override;
  void set_lidar_state(const LidarState& state) override {
    lidar_weak_ = state.weak;
    lidar_settled_ = state.settled;
  }
  /// A configured stream's gate is open.
  bool active() const override;

  const std::array<VisualStreamFigures, 3>& figures() const { return figures_; }
  const CameraFactorsConfig& config() const { return config_; }
  const VisualLandmarks& landmarks(vision::FrontendMode stream) const {
    return landmarks_[static_cast<std::size_t>(stream)];
  }

 private:
  struct StoredFrame {
    HostTime stamp;
    std::vector<FrameFeature> features;  ///< id order
    double omega = 1;
  };
  struct Stream {
    std::deque<StoredFrame> frames;  ///< stamp order
    int below = 0;                   ///< consecutive frames under min_confidence
    int above = 0;                   ///< consecutive frames at or over rejoin_confidence
  };
  /// The last frame of `s` at or before `t`, at most max_frame_age old; null if none.
  const StoredFrame* frame_before(const Stream& s, HostTime t) const;
  /// The motion of `stream` from window state k (k >= 1: the bridge to its frame needs the state
  /// before it) to the state `next`; counts a failure in the figures only if `count_failure`.
  std::optional<estimator::RelativeMotion> measure(std::size_t stream,
                                                   const estimator::SlidingWindow& window,
                                                   std::size_t k, const imu::ImuState& next,
                                                   bool count_failure);
  void gate(std::size_t stream, double confidence, double gradient);
  /// The thermal stream waits while another stream's gate is open (thermal_standby).
  bool standing_by(std::size_t stream) const;

  CameraFactorsConfig config_;
  std::array<Stream, 3> streams_;
  std::array<VisualStreamFigures, 3> figures_{};
  std::array<VisualLandmarks, 3> landmarks_;    // per stream, with CameraCoupling::kLandmarks
  std::array<std::uint64_t, 3> observed_id_{};  // per stream: the last state given a frame
  std::array<HostTime, 3> observed_stamp_{};    // and that frame's stamp
  std::array<double, 3> residual_scale_{1.0, 1.0, 1.0};    // per stream, see residual_scaling
  std::array<std::optional<HostTime>, 3> keyframe_stamp_;  // per stream, see keyframe_states
  bool thermal_gave_motion_ = false;  // since it last stood by (thermal_standby, active())
  bool lidar_weak_ = true;            // keyframes only then (see keyframe_states)
  bool lidar_settled_ = false;        // strong_lidar_floor_translation_m only then
  std::vector<double> residuals_;     // scratch
};

}  // namespace posed::fusion
