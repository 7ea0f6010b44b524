#pragma once
// Line features of seed 001 (after PL-VIO): segments from the Line Segment Detector (LSD, von
// Gioi et al. 2010) tracked from frame to frame. Seed 001 describes them with LBD descriptors,
// which are in OpenCV's contrib modules, not in Debian's core ones; it also requires a tracked
// line to keep at least 2 tracked points. We track lines by those points alone: `samples`
// points along each segment go through KLT, a segment survives when at least 2 are found and
// they stay on a straight line (within `max_line_residual_px`), and its new end points follow
// the least-squares fit of the tracked samples. New LSD segments fill up to `max_lines`, longest
// first, skipping those that duplicate a tracked one.
//
// Cost: LSD runs on the whole image each frame (several milliseconds at 640x480; see the bench),
// which is why lines are off by default (FrontendConfig::lines).

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace posed::vision {

struct LineConfig {
  int max_lines = 50;                  ///< [1]
  double min_length_px = 30;           ///< shorter LSD segments are ignored [px]
  int samples = 5;                     ///< points tracked along each segment [1]
  double max_line_residual_px = 1.5;   ///< tracked samples off their fitted line [px]
  double duplicate_distance_px = 5;    ///< a detection this close to a tracked line ... [px]
  double duplicate_angle_rad = 0.087;  ///< ... and this parallel (5 deg) duplicates it [rad]
  double lsd_scale = 0.8;              ///< LSD's image scale [-]
  int klt_window_px = 21;              ///< [px]
  int klt_pyramid_levels = 3;          ///< [1]
};

struct LineFeature {
  std::uint64_t id = 0;      ///< stable while tracked, never reused
  Eigen::Vector2f start_px;  ///< end point in the (distorted) image [px]
  Eigen::Vector2f end_px;    ///< other end point [px]
  std::uint32_t length = 1;  ///< frames seen, this one included [1]
};

struct LineStats {
  int previous = 0;  ///< lines carried in [1]
  int tracked = 0;   ///< of those, tracked into this frame [1]
  int detected = 0;  ///< new lines added [1]
  int total = 0;     ///< lines now [1]
};

class LineTracker {
 public:
  explicit LineTracker(const LineConfig& config);
  LineStats track(const cv::Mat& grey);
  const std::vector<LineFeature>& lines() const { return lines_; }

 private:
  LineConfig config_;
  cv::Ptr<cv::LineSegmentDetector> lsd_;
  std::uint64_t next_id_ = 0;
  std::vector<LineFeature> lines_;
  cv::Mat previous_;
  std::vector<cv::Point2f> from_, to_;
  std::vector<std::uint8_t> status_;
  std::vector<float> error_;
  std::vector<cv::Vec4f> segments_;
};

}  // namespace posed::vision
