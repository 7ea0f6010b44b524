#include "core/vision/line_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/video/tracking.hpp>

namespace posed::vision {
namespace {

/// Distance of `p` from the infinite line through a, b [px].
float line_distance(const Eigen::Vector2f& a, const Eigen::Vector2f& b, const Eigen::Vector2f& p) {
  const Eigen::Vector2f d = b - a;
  const float n = d.norm();
  if (n <= 0.f) return (p - a).norm();
  return std::abs(d.x() * (p.y() - a.y()) - d.y() * (p.x() - a.x())) / n;
}

/// Angle between two undirected segments [rad, 0..pi/2].
float line_angle(const Eigen::Vector2f& d1, const Eigen::Vector2f& d2) {
  const float c = std::abs(d1.normalized().dot(d2.normalized()));
  return std::acos(std::min(1.f, c));
}

}  // namespace

LineTracker::LineTracker(const LineConfig& config)
    : config_(config), lsd_(cv::createLineSegmentDetector(cv::LSD_REFINE_STD, config.lsd_scale)) {}

LineStats LineTracker::track(const cv::Mat& grey) {
  CV_Assert(grey.type() == CV_8UC1);
  LineStats stats;
  stats.previous = static_cast<int>(lines_.size());
  const int samples = std::max(2, config_.samples);

  if (!lines_.empty() && !previous_.empty() && previous_.size() == grey.size()) {
    from_.clear();
    for (const LineFeature& l : lines_) {
      for (int k = 0; k < samples; ++k) {
        const float t = static_cast<float>(k) / static_cast<float>(samples - 1);
        const Eigen::Vector2f p = l.start_px + t * (l.end_px - l.start_px);
        from_.emplace_back(p.x(), p.y());
      }
    }
    to_ = from_;
    cv::calcOpticalFlowPyrLK(previous_, grey, from_, to_, status_, error_,
                             cv::Size(config_.klt_window_px, config_.klt_window_px),
                             config_.klt_pyramid_levels);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < lines_.size(); ++i) {
      // Least squares of the tracked samples' positions against their parameter t: p(t) = a + t b.
      double st = 0, stt = 0, n = 0;
      Eigen::Vector2d sp = Eigen::Vector2d::Zero(), stp = Eigen::Vector2d::Zero();
      for (int k = 0; k < samples; ++k) {
        const std::size_t j = i * static_cast<std::size_t>(samples) + static_cast<std::size_t>(k);
        const cv::Point2f& q = to_[j];
        if (status_[j] == 0 || q.x < 0 || q.y < 0 || q.x > static_cast<float>(grey.cols - 1) ||
            q.y > static_cast<float>(grey.rows - 1)) {
          continue;
        }
        const double t = static_cast<double>(k) / (samples - 1);
        n += 1;
        st += t;
        stt += t * t;
        sp += Eigen::Vector2d(q.x, q.y);
        stp += t * Eigen::Vector2d(q.x, q.y);
      }
      const double det = n * stt - st * st;
      if (n < 2 || std::abs(det) < 1e-12) continue;  // seed 001: at least 2 tracked points
      const Eigen::Vector2d b = (n * stp - st * sp) / det;
      const Eigen::Vector2d a = (sp - st * b) / n;
      const Eigen::Vector2f start = a.cast<float>(), end = (a + b).cast<float>();
      bool straight = true;
      for (int k = 0; k < samples && straight; ++k) {
        const std::size_t j = i * static_cast<std::size_t>(samples) + static_cast<std::size_t>(k);
        if (status_[j] == 0) continue;
        straight = line_distance(start, end, Eigen::Vector2f(to_[j].x, to_[j].y)) <=
                   config_.max_line_residual_px;
      }
      if (!straight || (end - start).norm() < 0.5 * config_.min_length_px) continue;
      LineFeature l = lines_[i];
      l.start_px = start;
      l.end_px = end;
      ++l.length;
      lines_[kept++] = l;
    }
    lines_.resize(kept);
    stats.tracked = static_cast<int>(kept);
  } else {
    lines_.clear();
  }

  if (static_cast<int>(lines_.size()) < config_.max_lines) {
    lsd_->detect(grey, segments_);
    std::vector<std::size_t> order(segments_.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    const auto length = [&](std::size_t i) {
      const cv::Vec4f& s = segments_[i];
      return std::hypot(s[2] - s[0], s[3] - s[1]);
    };
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return length(a) > length(b); });
    for (const std::size_t i : order) {
      if (static_cast<int>(lines_.size()) >= config_.max_lines) break;
      if (length(i) < config_.min_length_px) break;
      const cv::Vec4f& s = segments_[i];
      const Eigen::Vector2f a(s[0], s[1]), b(s[2], s[3]);
      const Eigen::Vector2f mid = 0.5f * (a + b);
      bool duplicate = false;
      for (const LineFeature& l : lines_) {
        const Eigen::Vector2f lmid = 0.5f * (l.start_px + l.end_px);
        const float half = 0.5f * (l.end_px - l.start_px).norm();
        if (line_distance(l.start_px, l.end_px, mid) <= config_.duplicate_distance_px &&
            (mid - lmid).norm() <= half &&
            line_angle(b - a, l.end_px - l.start_px) <= config_.duplicate_angle_rad) {
          duplicate = true;
          break;
        }
      }
      if (duplicate) continue;
      LineFeature l;
      l.id = next_id_++;
      l.start_px = a;
      l.end_px = b;
      lines_.push_back(l);
      ++stats.detected;
    }
  }
  stats.total = static_cast<int>(lines_.size());
  grey.copyTo(previous_);
  return stats;
}

}  // namespace posed::vision
