#pragma once
// One camera stream's features as landmarks of the window (LVI-SAM's VIS, VINS-Mono): a feature
// first seen with lidar depth at the newest state becomes a 3-D point fixed in that state's body
// frame (its anchor), and every later frame of a state that still sees it adds a reprojection
// factor between the anchor's pose and that state's (estimator::LandmarkFactor). A feature seen
// over the whole window thus ties every state to one point, where a frame-to-frame motion tied
// only neighbours; and no observation is chosen by the window's guess before the solve: each one
// enters under a Huber kernel, and those the solve cannot explain are dropped afterwards.
//
// Why the depth is held at the lidar's instead of estimated (an inverse-depth block per
// landmark): the front end's lidar depth is good to a few centimetres (98 % of features within
// 10 % on the simulated corridor), a landmark block would make every landmark a column of the
// marginalisation, and LVI-SAM holds lidar-depth landmarks constant too. A feature without depth
// when it is first seen waits until a frame gives it one.
//
// When the anchor leaves the window its factors are marginalised with it; a feature still tracked
// is anchored afresh at the next state whose frame gives it depth.
//
// Deterministic: features are taken in the frame's order (id order); the table is only looked up.

#include <Eigen/Geometry>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/estimator/sliding_window.hpp"
#include "core/estimator/window_factor.hpp"
#include "core/fusion/frame_motion.hpp"

namespace posed::fusion {

struct VisualLandmarksConfig {
  double focal_px = 600;  ///< focal length of the grid the features are in [px]
  /// an observation further than this from where the window's current estimate projects its
  /// landmark is not added: a wrong match or a point of the other side of a depth edge, not a
  /// guess that is a few pixels off (the Huber kernel weighs those) [px]
  double gate_px = 20;
  /// after a solve, a landmark whose newest observation sits further than this from the solution
  /// takes no more observations [sigma]
  double outlier_sigma = 15;
  double huber_sigma = 3;    ///< Huber threshold of the factors [sigma]
  double min_depth_m = 0.3;  ///< nearer lidar depths do not anchor a landmark [m]
  double max_depth_m = 40;   ///< nor further ones: their parallax is too small [m]
  int max_observations = 0;  ///< per frame (0: every feature) [1]
  /// A landmark whose observation is nearer to where it was seen at its anchor than to where the
  /// window's estimate moves it, when that estimate moves it by more than this, is dropped: a
  /// corner of the lamp's shading on a plain wall or of lens dirt holds still in the image and
  /// says the camera stood still (frame_motion.hpp's still_flow_sigma, here in pixels) [px]
  double still_flow_px = 2;
};

struct VisualLandmarksFigures {
  std::uint64_t factors = 0;   ///< factors added [1]
  std::uint64_t anchored = 0;  ///< landmarks created [1]
  std::uint64_t gated = 0;     ///< observations not added (beyond gate_px) [1]
  std::uint64_t outliers = 0;  ///< landmarks dropped after a solve [1]
  std::uint64_t still = 0;     ///< landmarks dropped as holding still in the image [1]
  std::size_t tracked = 0;     ///< landmarks in the table now [1]
  int last_factors = 0;        ///< factors added at the newest state [1]
};

class VisualLandmarks {
 public:
  explicit VisualLandmarks(const VisualLandmarksConfig& config) : config_(config) {}

  /// State `observer` of `window` sees `features` (a frame of this stream, features in id order)
  /// from a camera at `T_body_cam` in its body frame: adds a factor of `kind` for each landmark
  /// anchored at an older state, anchors new landmarks. `sqrt_information` whitens a normalised
  /// image coordinate (focal length over pixel sigma, over √ω). Observers come in state order
  /// (the newest, or the one before it when its frame came late). Returns the factors added.
  int add(estimator::SlidingWindow& window, std::size_t observer, estimator::FactorKind kind,
          const std::vector<FrameFeature>& features, const Eigen::Isometry3d& T_body_cam,
          double sqrt_information);
  /// After a solve: drops landmarks whose observation from the last observer the solution does
  /// not explain.
  void after_solve(const estimator::SlidingWindow& window);
  /// Forgets every landmark (the stream left the estimate).
  void clear() { landmarks_.clear(); }

  const VisualLandmarksFigures& figures() const { return figures_; }
  /// Landmarks in the table now [1].
  std::size_t tracked() const { return landmarks_.size(); }

 private:
  struct Landmark {
    std::uint64_t anchor_id = 0;  ///< the state whose body frame holds X_anchor
    Eigen::Vector3d X_anchor = Eigen::Vector3d::Zero();           ///< [m]
    Eigen::Vector2d anchor_normalised = Eigen::Vector2d::Zero();  ///< where it was seen there
    std::uint64_t last_id = 0;  ///< the newest state with a factor on it (0: none)
    Eigen::Isometry3d T_body_cam_last = Eigen::Isometry3d::Identity();
    Eigen::Vector2d observed_last = Eigen::Vector2d::Zero();
    double sqrt_information_last = 0;
    bool outlier = false;
  };

  VisualLandmarksConfig config_;
  std::uint64_t last_observer_id_ = 0;                     // the state the last add() observed from
  std::unordered_map<std::uint64_t, Landmark> landmarks_;  // by feature id
  VisualLandmarksFigures figures_;
};

}  // namespace posed::fusion
