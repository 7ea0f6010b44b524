#pragma once
// What the visual-thermal front end hands to the back end for one frame pair.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>
#include <vector>

#include "core/time.hpp"
#include "core/vision/depth_associator.hpp"
#include "core/vision/image_quality.hpp"
#include "core/vision/line_tracker.hpp"
#include "core/vision/scene_nuc.hpp"
#include "core/vision/thermal_aligner.hpp"

namespace posed::vision {

/// Which image the features are tracked on (the paper's Table 2 compares the three).
enum class FrontendMode : std::uint8_t {
  kVisible,  ///< enhanced visible only; the thermal frame is ignored
  kThermal,  ///< preprocessed thermal only, registered to the visible camera's pixel grid
  kFused,    ///< DWT fusion of both (seed 000)
};
std::string_view to_string(FrontendMode mode);

enum class FrontendStatus : std::uint8_t {
  kOk,
  kVisibleUnusable,  ///< the mode needs the visible image and it is missing or malformed
  kThermalUnusable,  ///< the mode needs the thermal image and it is missing or malformed
};
std::string_view to_string(FrontendStatus status);

/// One tracked point feature. Geometry is always the visible camera's (thermal-only mode tracks
/// the registered thermal image), so the back end needs one camera model.
struct FrontendFeature {
  std::uint64_t id = 0;                                ///< stable while tracked, never reused
  Eigen::Vector2f pixel_px = Eigen::Vector2f::Zero();  ///< in the distorted visible image [px]
  /// undistorted (x/z, y/z) in the visible camera frame [-]
  Eigen::Vector2d normalised = Eigen::Vector2d::Zero();
  /// depth z in the visible camera frame from the lidar, or where it gives none from the
  /// D435i's depth image [m]; NaN when not associated
  double depth_m = std::numeric_limits<double>::quiet_NaN();
  DepthStatus depth_status = DepthStatus::kNoPoints;
  bool depth_from_stereo = false;  ///< depth_m is the depth image's, not the lidar's
  std::uint32_t track_length = 1;  ///< frames seen, this one included [1]
  /// change of `normalised` since the previous frame over the stamp difference [1/s]; zero for
  /// a new feature
  Eigen::Vector2d velocity_per_s = Eigen::Vector2d::Zero();
  /// How well the feature's image patch fixes its position in each direction: the patch's
  /// structure tensor (the sum of gradient outer products over the KLT window, in pixel axes)
  /// over its largest eigenvalue, so 1 along the best-fixed direction. A corner is near the
  /// identity; a patch on a straight edge is near 0 along the edge, where KLT cannot see motion
  /// (the aperture problem) and its track slides or sticks. Identity where not computed [-]
  Eigen::Matrix2d patch_shape = Eigen::Matrix2d::Identity();
  /// its image has moved as a point of the world would (fusion::StaticTrackFilter); until then
  /// it may be fixed to the camera and does not enter the estimate
  bool verified = false;
};

/// Per-stream image quality (seed 002). `valid` is false for a stream this mode does not build.
struct StreamQualities {
  ImageQuality visible;  ///< enhanced visible grey
  ImageQuality thermal;  ///< registered thermal grey
  ImageQuality fused;    ///< DWT fusion
};

struct FrontendCounts {
  int previous = 0;                 ///< features carried in from the previous frame [1]
  int tracked = 0;                  ///< of those, tracked by KLT (and the round trip) [1]
  int ransac_inliers = 0;           ///< of those, kept by the fundamental-matrix RANSAC [1]
  int crowded = 0;                  ///< of those, dropped within min_distance of a longer track [1]
  int extracted = 0;                ///< new features detected this frame [1]
  int features = 0;                 ///< features output [1]
  int depth_associated = 0;         ///< of those, with a depth (lidar or depth image) [1]
  int stereo_depth_associated = 0;  ///< of those, from the D435i's depth image [1]
  int lidar_points = 0;             ///< lidar points in the depth kd-tree after culling [1]
  int stereo_points = 0;            ///< depth-image points in its kd-tree after culling [1]
  int lines = 0;                    ///< line features output (0 when lines are off) [1]
  /// seed 001's match success rate: inliers over the features carried in [0..1]; NaN on the
  /// first frame
  double match_success_rate() const {
    return previous > 0 ? static_cast<double>(ransac_inliers) / previous
                        : std::numeric_limits<double>::quiet_NaN();
  }
};

struct FrontendFrame {
  /// the tracked image's stamp: the visible frame's (visible, fused) or the thermal frame's
  HostTime stamp;
  FrontendMode mode = FrontendMode::kFused;
  FrontendStatus status = FrontendStatus::kOk;
  std::vector<FrontendFeature> features;  ///< in id order
  std::vector<LineFeature> lines;         ///< empty when lines are off
  StreamQualities quality;
  FrontendCounts counts;
  AlignStats thermal_alignment;  ///< how the thermal frame was registered (when used)
  SceneNucStats thermal_nuc;     ///< what the scene-based NUC did (when enabled)
  double visible_gamma = 1;      ///< adaptive gamma applied to the visible image [-]
};

/// The steps of one frame pair, for profilers (`posectl bench frontend`): the front end calls
/// the probe at each step's start and end; it reads no clock itself.
enum class FrontendStep : std::uint8_t {
  kEnhance,   ///< visible: adaptive gamma + CLAHE, to grey
  kThermal,   ///< thermal: one remap (undistort, FOV, resample, register, rotate), 16->8 bit
  kFusion,    ///< DWT fusion
  kQuality,   ///< gradient and noise metrics of every stream built (before and after fusion)
  kTracking,  ///< KLT, RANSAC, new corners (and lines when on)
  kDepth,     ///< lidar cloud to the kd-tree, depth per feature
};
inline constexpr std::array<std::string_view, 6> kFrontendStepNames = {
    "enhance", "thermal", "fusion", "quality", "tracking", "depth"};

class FrontendStepProbe {
 public:
  virtual ~FrontendStepProbe() = default;
  virtual void begin(FrontendStep step) = 0;
  virtual void end(FrontendStep step) = 0;
};

}  // namespace posed::vision
