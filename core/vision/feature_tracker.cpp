#include "core/vision/feature_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "core/vision/corner_selection.hpp"

namespace posed::vision {

int reject_with_fundamental(const std::vector<cv::Point2f>& previous,
                            const std::vector<cv::Point2f>& current, double threshold_px,
                            double confidence, int max_iterations,
                            std::vector<std::uint8_t>& inlier) {
  CV_Assert(previous.size() == current.size());
  inlier.assign(previous.size(), 1);
  if (previous.size() < 8) return static_cast<int>(previous.size());
  std::vector<std::uint8_t> mask;
  const cv::Mat F = cv::findFundamentalMat(previous, current, cv::FM_RANSAC, threshold_px,
                                           confidence, std::max(1, max_iterations), mask);
  if (F.empty() || mask.size() != previous.size()) return static_cast<int>(previous.size());
  int count = 0;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    inlier[i] = mask[i] != 0 ? 1 : 0;
    count += inlier[i];
  }
  return count;
}

FeatureTracker::FeatureTracker(const TrackerConfig& config, const PinholeCamera& camera)
    : config_(config), camera_(camera), undistorter_(camera) {}

void FeatureTracker::reset() {
  tracks_.clear();
  previous_pyramid_.clear();
}

void FeatureTracker::drop(const std::vector<std::uint64_t>& ids) {
  std::erase_if(tracks_,
                [&](const Track& t) { return std::binary_search(ids.begin(), ids.end(), t.id); });
}

Eigen::Vector2d FeatureTracker::normalise(const cv::Point2f& pixel) const {
  return undistorter_.normalised(Eigen::Vector2d(pixel.x, pixel.y));
}

TrackStats FeatureTracker::track(const cv::Mat& grey, const cv::Mat& detect_mask) {
  CV_Assert(grey.type() == CV_8UC1);
  TrackStats stats;
  const cv::Size window(config_.klt_window_px, config_.klt_window_px);
  // A copy, not a view of `grey` (tryReuseInputImage = false): the caller may overwrite its
  // image before the next frame, which tracks from this pyramid.
  cv::buildOpticalFlowPyramid(grey, pyramid_, window, config_.klt_pyramid_levels, true,
                              cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT, false);
  stats.previous = static_cast<int>(tracks_.size());

  if (!tracks_.empty() && !previous_pyramid_.empty()) {
    const std::size_t n = tracks_.size();
    from_.resize(n);
    for (std::size_t i = 0; i < n; ++i) from_[i] = tracks_[i].pixel;
    to_ = from_;
    const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                    config_.klt_max_iterations, config_.klt_epsilon_px);
    cv::calcOpticalFlowPyrLK(previous_pyramid_, pyramid_, from_, to_, status_, error_, window,
                             config_.klt_pyramid_levels, criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
    if (config_.forward_backward_check) {
      back_ = from_;
      // Back from where the forward pass ended, starting at the point it came from: a correct
      // track is already within a pixel or two, so the finest level alone suffices (a quarter of
      // the forward pass's cost).
      cv::calcOpticalFlowPyrLK(pyramid_, previous_pyramid_, to_, back_, back_status_, error_,
                               window, 0, criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
      const double max_sq = config_.max_forward_backward_px * config_.max_forward_backward_px;
      for (std::size_t i = 0; i < n; ++i) {
        const cv::Point2f d = back_[i] - from_[i];
        if (back_status_[i] == 0 || d.dot(d) > max_sq) status_[i] = 0;
      }
    }
    const float border = static_cast<float>(config_.border_px);
    const float max_x = static_cast<float>(grey.cols - 1) - border;
    const float max_y = static_cast<float>(grey.rows - 1) - border;
    for (std::size_t i = 0; i < n; ++i) {
      const cv::Point2f& p = to_[i];
      if (!(p.x >= border && p.y >= border && p.x <= max_x && p.y <= max_y)) status_[i] = 0;
    }

    // RANSAC over the survivors, on undistorted pixels (pinhole with the same K).
    from_undistorted_.clear();
    to_undistorted_.clear();
    std::vector<Eigen::Vector2d> normalised(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (status_[i] == 0) continue;
      normalised[i] = normalise(to_[i]);
      if (!normalised[i].allFinite()) {
        status_[i] = 0;
        continue;
      }
      const Eigen::Vector2d& a = tracks_[i].normalised;
      const Eigen::Vector2d& b = normalised[i];
      from_undistorted_.emplace_back(static_cast<float>(camera_.fx * a.x() + camera_.cx),
                                     static_cast<float>(camera_.fy * a.y() + camera_.cy));
      to_undistorted_.emplace_back(static_cast<float>(camera_.fx * b.x() + camera_.cx),
                                   static_cast<float>(camera_.fy * b.y() + camera_.cy));
    }
    stats.klt_tracked = static_cast<int>(from_undistorted_.size());
    if (config_.ransac) {
      stats.ransac_inliers = reject_with_fundamental(
          from_undistorted_, to_undistorted_, config_.ransac_threshold_px,
          config_.ransac_confidence, config_.ransac_max_iterations, inlier_);
    } else {
      inlier_.assign(from_undistorted_.size(), 1);
      stats.ransac_inliers = stats.klt_tracked;
    }

    std::size_t kept = 0, survivor = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (status_[i] == 0) continue;
      if (inlier_[survivor++] == 0) continue;
      Track t = tracks_[i];
      t.pixel = to_[i];
      t.normalised = normalised[i];
      ++t.length;
      tracks_[kept++] = t;
    }
    tracks_.resize(kept);
  } else {
    tracks_.clear();
  }

  detect(grey, detect_mask, stats);
  stats.total = static_cast<int>(tracks_.size());
  std::swap(previous_pyramid_, pyramid_);
  return stats;
}

void FeatureTracker::mask_weak_corners() {
  if (corner_score_.empty()) return;
  const float median = nth_smallest(corner_score_, corner_score_.total() / 2);
  const double threshold = config_.corner_noise_factor * static_cast<double>(median);
  cv::Mat strong;
  cv::compare(corner_score_, threshold, strong, cv::CMP_GT);
  cv::bitwise_and(mask_, strong, mask_);
}

void FeatureTracker::detect(const cv::Mat& grey, const cv::Mat& detect_mask, TrackStats& stats) {
  // Corners are looked for on pyramid level `detect_level`; the mask lives at that resolution
  // too (its discs then cost a quarter per level). pyramid_ holds image and derivatives per
  // level: level l's image is element 2 l (fewer levels exist for tiny images).
  int level = std::clamp(config_.detect_level, 0, config_.klt_pyramid_levels);
  while (level > 0 && pyramid_.size() <= static_cast<std::size_t>(2 * level)) --level;
  const cv::Mat& image = level == 0 ? grey : pyramid_[static_cast<std::size_t>(2 * level)];
  const double scale = static_cast<double>(1 << level);
  if (detect_mask.empty()) {
    mask_.create(image.size(), CV_8UC1);
    mask_.setTo(255);
  } else {
    CV_Assert(detect_mask.type() == CV_8UC1 && detect_mask.size() == grey.size());
    cv::resize(detect_mask, mask_, image.size(), 0, 0, cv::INTER_NEAREST);
  }
  // Full-resolution pixel p lies in level pixel (p + 0.5) / s - 0.5.
  const auto to_level = [scale](const cv::Point2f& p) {
    return cv::Point(static_cast<int>(std::lround((p.x + 0.5) / scale - 0.5)),
                     static_cast<int>(std::lround((p.y + 0.5) / scale - 0.5)));
  };

  // Longest tracks claim their disc first; a track inside an older one's disc is dropped, so the
  // set stays spread out (VINS-Mono's setMask).
  order_.resize(tracks_.size());
  std::iota(order_.begin(), order_.end(), std::size_t{0});
  std::stable_sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) {
    return tracks_[a].length > tracks_[b].length;
  });
  std::vector<std::uint8_t> keep(tracks_.size(), 0);
  // The disc covers pixels nearer than min_distance (cv::circle fills up to about r + 0.5), so
  // corners goodFeaturesToTrack placed exactly min_distance apart do not evict each other.
  const double min_distance = config_.min_distance_px / scale;
  const int radius = std::max(0, static_cast<int>(std::ceil(min_distance)) - 1);
  const cv::Rect inside(0, 0, mask_.cols, mask_.rows);
  for (const std::size_t i : order_) {
    const cv::Point p = to_level(tracks_[i].pixel);
    if (!inside.contains(p) || mask_.at<std::uint8_t>(p) == 0) continue;
    keep[i] = 1;
    cv::circle(mask_, p, radius, cv::Scalar(0), cv::FILLED);
  }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    if (keep[i] != 0) tracks_[kept++] = tracks_[i];
  }
  stats.crowded = static_cast<int>(tracks_.size() - kept);
  tracks_.resize(kept);

  const int wanted = config_.max_features - static_cast<int>(tracks_.size());
  if (wanted <= 0) return;
  // cv::goodFeaturesToTrack in two halves, so the score image serves the noise mask as well.
  cv::cornerMinEigenVal(image, corner_score_, config_.corner_block_size, 3);
  if (config_.corner_noise_factor > 0) mask_weak_corners();
  select_corners(corner_score_, mask_, wanted, config_.corner_quality, min_distance, corners_);
  const float border = static_cast<float>(config_.border_px);
  for (cv::Point2f c : corners_) {
    // Level pixel x covers full-resolution pixels [x s, x s + s - 1]: centre (x + 0.5) s - 0.5.
    c.x = static_cast<float>((c.x + 0.5) * scale - 0.5);
    c.y = static_cast<float>((c.y + 0.5) * scale - 0.5);
    if (c.x < border || c.y < border || c.x > static_cast<float>(grey.cols - 1) - border ||
        c.y > static_cast<float>(grey.rows - 1) - border) {
      continue;
    }
    Track t;
    t.id = next_id_++;
    t.pixel = c;
    t.normalised = normalise(c);
    if (!t.normalised.allFinite()) continue;
    tracks_.push_back(t);
    ++stats.extracted;
  }
}

}  // namespace posed::vision
