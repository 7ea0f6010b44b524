#pragma once
// Scene-based non-uniformity correction of the thermal stream: a microbolometer's fixed pattern
// (each element's and each column's offset, growing between the camera's flat-field corrections)
// is estimated from the video itself and subtracted, as the temporal high-pass NUC of Scribner et
// al. (1991), learning only while the image moves. Each pixel's offset is the running mean of
// its spatial high-pass I - box(I): while the camera moves, the scene's detail passes over a pixel
// and averages out, and what stays is the pixel's own offset. Without it, a thermal camera in a
// scene of little contrast (a smoky roadway, a plain wall) tracks its own pattern: corners that
// never move and tell the estimator the robot stands still.
//
// Updates are gated: when the low-passed image changes by less than `min_relative_change` of its
// spread between frames the camera is taken as still and the estimate is left alone (the scene
// held in place would be learnt as pattern and burnt into the output as its negative). After a
// flat-field correction (the shutter: frames freeze) the pattern starts afresh; reset() starts
// the estimate afresh too.
//
// What it cannot tell apart from the pattern is scene detail that holds still in the image while
// the camera moves (a corridor's edges converging on the vanishing point): learnt, it is
// subtracted as a faint fixed negative. A mask of strong edges (not learnt from) was tried and
// measured worse on the smoke roadway (docs/estimator.md).

#include <cstdint>
#include <opencv2/core/mat.hpp>

namespace posed::vision {

struct SceneNucConfig {
  bool enabled = false;
  /// updates a pixel's offset is averaged over once warmed up (an exponential average) [frames]
  double average_frames = 100;
  /// half-width of the box the spatial high-pass subtracts [px]
  int highpass_radius_px = 3;
  /// mean change of the low-passed image between frames, relative to its standard deviation,
  /// below which the camera is taken as still and nothing is learnt [1]
  double min_relative_change = 0.05;
};

struct SceneNucStats {
  bool updated = false;        ///< this frame updated the offsets
  std::uint64_t updates = 0;   ///< updates since the last reset [frames]
  double relative_change = 0;  ///< the gate's measure for this frame [1]
  double offset_rms = 0;       ///< RMS of the subtracted offsets [grey or counts]
};

class SceneNuc {
 public:
  explicit SceneNuc(const SceneNucConfig& config);

  /// `raw` (CV_8UC1 or CV_16UC1) -> `corrected` (same type and size). Learns from `raw` first
  /// when the gate lets it. A change of size starts afresh.
  SceneNucStats correct(const cv::Mat& raw, cv::Mat& corrected);

  /// Forget the offsets (the camera's shutter has just reset its pattern).
  void reset();

  const SceneNucConfig& config() const { return config_; }

 private:
  SceneNucConfig config_;
  cv::Mat frame_, low_, previous_low_, highpass_, offset_, change_;
  std::uint64_t updates_ = 0;
  bool has_previous_ = false;
};

}  // namespace posed::vision
