#pragma once
// The visual-thermal front end (issue 9): seeds 000, 001 and 002 composed.
//
//   visible (BGR/RGB/grey) -> enhance (001) ----------------------+
//                                                                   +-> DWT fusion (000)
//   thermal (8/16-bit) -> one remap: undistort, FOV (000 eq. 1-6),  |   -> KLT + RANSAC (001)
//                         resample, register, inter-stamp rotation -+   -> lidar depth (000)
//   image quality (002) of every stream built -> confidence and covariance weight omega
//
// Pure and deterministic: no clock, no I/O, no threads of its own (OpenCV's functions may use
// its internal thread pool; the runner decides with cv::setNumThreads), state only in the
// trackers and reusable buffers. Every image stays in the visible camera's pixel grid, so the
// features of all three modes share one camera model.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <span>

#include "core/measurements.hpp"
#include "core/vision/depth_associator.hpp"
#include "core/vision/dwt_fusion.hpp"
#include "core/vision/enhancer.hpp"
#include "core/vision/feature_tracker.hpp"
#include "core/vision/frontend_frame.hpp"
#include "core/vision/image_quality.hpp"
#include "core/vision/line_tracker.hpp"
#include "core/vision/pinhole_camera.hpp"
#include "core/vision/scene_nuc.hpp"
#include "core/vision/thermal_aligner.hpp"

namespace posed::vision {

struct FrontendConfig {
  FrontendMode mode = FrontendMode::kFused;
  PinholeCamera visible_camera;  ///< the D435i colour camera (M2DGR: 640x480)
  PinholeCamera thermal_camera;  ///< the PLUG 617 (M2DGR: 640x512)
  /// thermal camera pose in the visible camera frame (p_cam = T_cam_thermal p_thermal)
  Eigen::Isometry3d T_cam_thermal = Eigen::Isometry3d::Identity();
  EnhanceConfig visible_enhance;        ///< seed 001's enhancement of the visible stream
  EnhanceConfig thermal_enhance = [] {  ///< off by default: seed 000 fuses the thermal as is
    EnhanceConfig c;
    c.enabled = false;
    return c;
  }();
  SceneNucConfig thermal_nuc;  ///< the thermal camera's fixed pattern, learnt and subtracted
  ThermalAlignConfig thermal_align;
  FusionConfig fusion;
  bool assess_quality = true;
  QualityConfig quality;
  TrackerConfig tracker;
  bool lines = false;  ///< LSD line features (seed 001); several ms per frame
  /// FrontendFeature::patch_shape for every feature (the back end's aperture weighting needs
  /// it); otherwise each is left the identity
  bool patch_shapes = false;
  LineConfig line;
  DepthConfig depth;
  /// Depth from the D435i's depth image for the features the lidar gives none
  /// (FrontendInput::p_depth_cam_m). Its points are dense (one per few pixels), so three
  /// neighbours that span more than a few decimetres straddle a depth edge.
  DepthConfig stereo_depth = [] {
    DepthConfig c;
    c.max_span_m = 0.3;
    c.min_range_m = 0.3;
    c.max_range_m = 10.0;
    c.max_extrapolation_m = 0.1;
    return c;
  }();
};

/// One frame pair. cv::Mat headers may wrap driver buffers (see image_view.hpp); nothing is
/// kept after process() returns.
struct FrontendInput {
  HostTime visible_stamp;  ///< exposure midpoint of the visible frame
  HostTime thermal_stamp;  ///< exposure midpoint of the thermal frame
  cv::Mat visible;  ///< CV_8UC3 (B,G,R; R,G,B when visible_rgb) or CV_8UC1; any mode but kThermal
  bool visible_rgb = false;
  cv::Mat thermal;  ///< CV_8UC1 (AGC'd video) or CV_16UC1 (raw counts); any mode but kVisible
  /// camera rotation between the stamps: directions in the camera frame at the thermal stamp ->
  /// the camera frame at the visible stamp (see ThermalAligner::align); identity if unknown
  Eigen::Matrix3d R_camtv_camtt = Eigen::Matrix3d::Identity();
  /// recent deskewed lidar points in the visible camera frame at the tracked image's stamp [m];
  /// empty: no depth this frame
  std::span<const Eigen::Vector3f> p_cam_m;
  /// points of the D435i's depth image in the same frame [m]: depth for the features the lidar
  /// gives none (FrontendConfig::stereo_depth); empty: none this frame
  std::span<const Eigen::Vector3f> p_depth_cam_m;
};

/// Wraps core Images (either may be null) into an input without copying their pixels.
FrontendInput make_input(const Image* visible, const Image* thermal);

class VisualFrontend {
 public:
  /// Throws std::invalid_argument when a camera the mode uses has no valid intrinsics.
  explicit VisualFrontend(const FrontendConfig& config);
  ~VisualFrontend();
  VisualFrontend(const VisualFrontend&) = delete;
  VisualFrontend& operator=(const VisualFrontend&) = delete;

  /// Optional: called around every step of every frame (null: none).
  void set_probe(FrontendStepProbe* probe) { probe_ = probe; }

  /// Processes one frame pair into `out` (its vectors' capacity is reused). On a status other
  /// than kOk nothing is tracked and the trackers keep their state for the next frame.
  FrontendStatus process(const FrontendInput& input, FrontendFrame& out);

  /// Stops tracking the features with these ids (sorted ascending): the caller found them to be
  /// no part of the world (fusion::StaticTrackFilter).
  void drop_tracks(const std::vector<std::uint64_t>& ids) { tracker_.drop(ids); }

  /// The thermal camera's shutter closed (its video froze): its fixed pattern starts afresh, and
  /// so does what the scene-based NUC learnt of it.
  void thermal_shutter() { thermal_nuc_.reset(); }

  /// The grey images of the last frame (visible size), for inspection and annotation; empty for
  /// streams the mode does not build.
  const cv::Mat& visible_grey() const { return visible_grey_; }
  const cv::Mat& thermal_grey() const { return thermal_grey_; }
  const cv::Mat& fused_grey() const { return fused_grey_; }
  /// The image the features were tracked on.
  const cv::Mat& tracked_grey() const;

  const FrontendConfig& config() const { return config_; }

 private:
  void begin(FrontendStep s) {
    if (probe_ != nullptr) probe_->begin(s);
  }
  void end(FrontendStep s) {
    if (probe_ != nullptr) probe_->end(s);
  }

  FrontendConfig config_;
  Enhancer visible_enhancer_;
  Enhancer thermal_enhancer_;
  std::unique_ptr<ThermalAligner> aligner_;  // only when the mode uses the thermal stream
  SceneNuc thermal_nuc_;
  DwtFusion fusion_;
  QualityAssessor quality_;
  FeatureTracker tracker_;
  LineTracker line_tracker_;
  DepthAssociator depth_;
  DepthAssociator stereo_depth_;
  FrontendStepProbe* probe_ = nullptr;

  cv::Mat visible_grey_, thermal_grey_, thermal_aligned_, thermal_native_, fused_grey_;
  cv::Mat thermal_native_enhanced_, thermal_corrected_;
  cv::Mat visible_denoised_, thermal_denoised_;
  cv::Mat thermal_detect_mask_;  // thermal mode: where new corners may be found  // fusion inputs
                                 // when FusionConfig::denoise
  // previous frame's features (id order) for the velocities
  std::vector<std::pair<std::uint64_t, Eigen::Vector2d>> previous_;
  HostTime previous_stamp_;
  bool has_previous_ = false;
};

}  // namespace posed::vision
