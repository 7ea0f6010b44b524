#pragma once
// Point tracking of seed 001 (§ visual features, after VINS-Mono's front end): KLT sparse optical
// flow carries the features from frame to frame, a RANSAC fundamental matrix rejects the
// outliers, and new Shi-Tomasi corners top the set up to `max_features` (seed 001 keeps 200-400
// per frame) away from existing ones (a disc of `min_distance_px` around each, longest tracks
// first). Every feature keeps its id while it is tracked; ids are never reused.
//
// Additions to seed 001: a forward-backward KLT check (a point must track back to within
// `max_forward_backward_px` of where it came from), and RANSAC on undistorted pixel coordinates
// (the lens's distortion would otherwise bend the epipolar lines and reject good tracks near
// the borders).

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>
#include <vector>

#include "core/vision/pinhole_camera.hpp"
#include "core/vision/undistorter.hpp"

namespace posed::vision {

struct TrackerConfig {
  int max_features = 300;                ///< target count, seed 001: 200-400 [1]
  double min_distance_px = 20;           ///< between features [px]
  int klt_window_px = 15;                ///< KLT window side (VINS-Mono 21, OpenVINS 15) [px]
  int klt_pyramid_levels = 3;            ///< pyramid levels above the image [1]
  int klt_max_iterations = 30;           ///< per level [1]
  double klt_epsilon_px = 0.01;          ///< convergence [px]
  bool forward_backward_check = true;    ///< track back and compare
  double max_forward_backward_px = 0.5;  ///< round-trip error allowed [px]
  bool ransac = true;                    ///< fundamental-matrix outlier rejection
  double ransac_threshold_px = 1.0;      ///< distance to the epipolar line [px]
  double ransac_confidence = 0.99;       ///< [0..1]
  /// RANSAC's draws at most. OpenCV draws until the confidence is reached for the inlier share
  /// found so far, up to this: 1000 (its default) is the 99 % for 48 % inliers, and draws on a
  /// frame in smoke or darkness, where few tracks agree, cost several milliseconds [1]
  int ransac_max_iterations = 1000;
  double corner_quality = 0.01;  ///< Shi-Tomasi: fraction of the best corner's score [-]
  int corner_block_size = 3;     ///< Shi-Tomasi window [px]
  /// pyramid level new corners are detected on (0 = full resolution): on 640x480 the Shi-Tomasi
  /// response costs ~3 ms at level 0, a quarter at level 1, and KLT then tracks the patch
  /// around the corner wherever within its pixel it was placed [1]
  int detect_level = 1;
  int border_px = 2;  ///< features closer to the edge are dropped [px]
  /// a new corner's Shi-Tomasi score must exceed this multiple of the image's median score
  /// (0: off). On a plain, noisy surface (a corridor wall lit by the headlight, a thermal
  /// image of uniform walls with fixed-pattern noise) every "corner" is noise over shading that
  /// does not move in the image, and KLT follows it as a feature that never moves: a camera
  /// that seems to stand still while it drives. The median score is that noise floor wherever
  /// most of the image is untextured, and below any real corner elsewhere [-]
  double corner_noise_factor = 0;
};

/// One tracked point.
struct Track {
  std::uint64_t id = 0;        ///< stable while tracked, never reused
  cv::Point2f pixel;           ///< in the (distorted) image [px]
  Eigen::Vector2d normalised;  ///< undistorted (x/z, y/z) [-]
  std::uint32_t length = 1;    ///< frames it has been seen in, this one included [1]
};

/// What one frame did to the tracks.
struct TrackStats {
  int previous = 0;        ///< tracks carried in from the last frame [1]
  int klt_tracked = 0;     ///< of those, found by KLT (and the round trip), inside the image [1]
  int ransac_inliers = 0;  ///< of those, consistent with the fundamental matrix [1]
  int crowded = 0;    ///< of those, dropped for lying within min_distance of a longer track [1]
  int extracted = 0;  ///< new corners added [1]
  int total = 0;      ///< tracks now [1]
};

/// RANSAC fundamental-matrix rejection on matched undistorted pixel coordinates: clears
/// `inlier[i]` for outliers. With fewer than 8 matches nothing is rejected. Deterministic
/// (OpenCV's RANSAC seeds its generator on every call). Returns the inlier count.
int reject_with_fundamental(const std::vector<cv::Point2f>& previous,
                            const std::vector<cv::Point2f>& current, double threshold_px,
                            double confidence, int max_iterations,
                            std::vector<std::uint8_t>& inlier);

class FeatureTracker {
 public:
  /// `camera`: the intrinsics of the images to be tracked (to undistort for RANSAC and for the
  /// normalised coordinates).
  FeatureTracker(const TrackerConfig& config, const PinholeCamera& camera);

  /// Tracks into `grey` (CV_8UC1, the camera's size). `detect_mask` (CV_8UC1, or empty for
  /// everywhere): where new corners may be detected.
  TrackStats track(const cv::Mat& grey, const cv::Mat& detect_mask);

  const std::vector<Track>& tracks() const { return tracks_; }
  /// Forgets every track (ids continue).
  void reset();
  /// Forgets the tracks with these ids (sorted ascending).
  void drop(const std::vector<std::uint64_t>& ids);

 private:
  Eigen::Vector2d normalise(const cv::Point2f& pixel) const;
  void detect(const cv::Mat& grey, const cv::Mat& detect_mask, TrackStats& stats);
  /// Clears mask_ where the corner score is within corner_noise_factor of the median.
  /// (from corner_score_, the detection level's cv::cornerMinEigenVal)
  void mask_weak_corners();

  TrackerConfig config_;
  PinholeCamera camera_;
  Undistorter undistorter_;
  std::uint64_t next_id_ = 0;
  std::vector<Track> tracks_;
  std::vector<cv::Mat> previous_pyramid_, pyramid_;
  // scratch
  std::vector<cv::Point2f> from_, to_, back_, from_undistorted_, to_undistorted_, corners_;
  std::vector<std::uint8_t> status_, back_status_, inlier_;
  std::vector<float> error_;
  std::vector<std::size_t> order_;
  cv::Mat mask_;  // at the detection level's resolution
  cv::Mat corner_score_;
};

}  // namespace posed::vision
