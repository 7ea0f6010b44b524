#include "core/vision/scene_nuc.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace posed::vision {

SceneNuc::SceneNuc(const SceneNucConfig& config) : config_(config) {
  if (config_.average_frames < 1 || config_.highpass_radius_px < 1 ||
      config_.min_relative_change < 0) {
    throw std::invalid_argument(
        "scene NUC: average_frames >= 1, highpass_radius_px >= 1 and min_relative_change >= 0 "
        "required");
  }
}

void SceneNuc::reset() {
  offset_.release();
  previous_low_.release();
  updates_ = 0;
  has_previous_ = false;
}

SceneNucStats SceneNuc::correct(const cv::Mat& raw, cv::Mat& corrected) {
  if (raw.type() != CV_8UC1 && raw.type() != CV_16UC1) {
    throw std::invalid_argument("scene NUC: thermal frame must be CV_8UC1 or CV_16UC1");
  }
  if (!offset_.empty() && offset_.size() != raw.size()) reset();
  raw.convertTo(frame_, CV_32F);
  const int k = 2 * config_.highpass_radius_px + 1;
  cv::boxFilter(frame_, low_, CV_32F, cv::Size(k, k), cv::Point(-1, -1), true, cv::BORDER_REFLECT);

  SceneNucStats stats;
  bool moving = false;
  if (has_previous_) {
    cv::absdiff(low_, previous_low_, change_);
    cv::Scalar mean, stddev;
    cv::meanStdDev(low_, mean, stddev);
    // A flat image has no scene detail to burn in: any change lets it learn.
    const double spread = std::max(stddev[0], 1e-6);
    stats.relative_change = cv::mean(change_)[0] / spread;
    moving = stats.relative_change >= config_.min_relative_change;
  }
  std::swap(previous_low_, low_);  // previous_low_ is this frame's from here on
  has_previous_ = true;

  if (offset_.empty()) offset_ = cv::Mat::zeros(raw.size(), CV_32F);
  if (moving) {
    // The frame's high-pass: the pattern, the scene's detail passing by, and noise.
    cv::subtract(frame_, previous_low_, highpass_);
    ++updates_;
    // A running mean while warming up, then an exponential one that follows the pattern's growth.
    const double alpha =
        std::max(1.0 / static_cast<double>(updates_), 1.0 / config_.average_frames);
    cv::addWeighted(offset_, 1.0 - alpha, highpass_, alpha, 0.0, offset_);
    stats.updated = true;
  }
  stats.updates = updates_;
  if (updates_ > 0) {
    stats.offset_rms =
        cv::norm(offset_, cv::NORM_L2) / std::sqrt(static_cast<double>(offset_.total()));
    cv::subtract(frame_, offset_, frame_);
    frame_.convertTo(corrected, raw.type());  // rounds and saturates
  } else {
    raw.copyTo(corrected);
  }
  return stats;
}

}  // namespace posed::vision
