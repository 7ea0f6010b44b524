#include "core/vision/feature_overlay.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace posed::vision {

void draw_label(cv::Mat& image, const std::string& text) {
  cv::putText(image, text, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 3,
              cv::LINE_AA);
  cv::putText(image, text, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
}

cv::Scalar track_colour(std::uint32_t track_length) {
  const double s = std::min(1.0, static_cast<double>(std::max(track_length, 1u) - 1) / 19.0);
  return s < 0.5 ? cv::Scalar(0, 510 * s, 255) : cv::Scalar(0, 255, 510 * (1 - s));
}

cv::Mat feature_overlay(const cv::Mat& tracked_grey, const FrontendFrame& frame) {
  cv::Mat out;
  cv::cvtColor(tracked_grey, out, cv::COLOR_GRAY2BGR);
  int with_depth = 0;
  for (const FrontendFeature& f : frame.features) {
    const cv::Point2f p(f.pixel_px.x(), f.pixel_px.y());
    cv::circle(out, p, 3, track_colour(f.track_length), cv::FILLED, cv::LINE_AA);
    if (std::isnan(f.depth_m)) continue;
    cv::circle(out, p, 6, cv::Scalar(255, 200, 0), 1, cv::LINE_AA);
    if (with_depth++ % 8 == 0) {  // every eighth: a label on each would cover the image
      char text[16];
      std::snprintf(text, sizeof text, "%.1f", f.depth_m);
      cv::putText(out, text, p + cv::Point2f(7, -7), cv::FONT_HERSHEY_PLAIN, 0.8,
                  cv::Scalar(255, 200, 0), 1, cv::LINE_AA);
    }
  }
  const double match = frame.counts.match_success_rate();
  char caption[160];
  std::snprintf(caption, sizeof caption,
                "%s: %d features, %d tracked, %d with lidar depth, match %.0f %%",
                std::string(to_string(frame.mode)).c_str(), frame.counts.features,
                frame.counts.ransac_inliers, frame.counts.depth_associated,
                100.0 * (std::isnan(match) ? 0.0 : match));
  draw_label(out, caption);
  return out;
}

}  // namespace posed::vision
