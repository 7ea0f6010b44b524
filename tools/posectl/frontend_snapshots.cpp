#include "tools/posectl/frontend_snapshots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace posed::posectl {

namespace {

/// White text outlined in black at the top left, readable on any image.
void label(cv::Mat& image, const std::string& text) {
  cv::putText(image, text, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0), 3,
              cv::LINE_AA);
  cv::putText(image, text, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
}

/// A grey panel in colour with a caption; black when the mode did not build the image.
cv::Mat panel(const cv::Mat& grey, const cv::Size& size, const std::string& caption) {
  cv::Mat out(size, CV_8UC3, cv::Scalar(0, 0, 0));
  if (!grey.empty()) {
    cv::Mat bgr;
    cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
    if (bgr.size() != size) cv::resize(bgr, bgr, size);
    bgr.copyTo(out);
  }
  if (!caption.empty()) label(out, caption);
  return out;
}

/// Track length as colour: new features red, through yellow, to green at 20 frames and more.
cv::Scalar track_colour(std::uint32_t length) {
  const double s = std::min(1.0, static_cast<double>(length - 1) / 19.0);
  return s < 0.5 ? cv::Scalar(0, 510 * s, 255) : cv::Scalar(0, 255, 510 * (1 - s));
}

}  // namespace

FrontendSnapshots::FrontendSnapshots(SnapshotOptions options) : options_(std::move(options)) {}

void FrontendSnapshots::on_frame(const vision::FrontendFrame& frame,
                                 const vision::VisualFrontend& frontend) {
  frames_.fetch_add(1, std::memory_order_relaxed);
  const auto m = static_cast<std::size_t>(frame.mode);
  const std::uint64_t index = seen_[m]++;
  if (options_.directory.empty() || saved_[m] >= options_.max_snapshots ||
      index % std::max<std::uint64_t>(1, options_.every_frames) != 0) {
    return;
  }
  const cv::Mat& tracked = frontend.tracked_grey();
  if (tracked.empty()) return;
  const cv::Size size = tracked.size();
  cv::Mat features = panel(tracked, size, "");
  int with_depth = 0;
  for (const vision::FrontendFeature& f : frame.features) {
    const cv::Point2f p(f.pixel_px.x(), f.pixel_px.y());
    cv::circle(features, p, 3, track_colour(f.track_length), cv::FILLED, cv::LINE_AA);
    if (!std::isnan(f.depth_m)) {
      cv::circle(features, p, 6, cv::Scalar(255, 200, 0), 1, cv::LINE_AA);
      if (with_depth++ % 8 == 0) {
        char text[16];
        std::snprintf(text, sizeof text, "%.1f", f.depth_m);
        cv::putText(features, text, p + cv::Point2f(7, -7), cv::FONT_HERSHEY_PLAIN, 0.8,
                    cv::Scalar(255, 200, 0), 1, cv::LINE_AA);
      }
    }
  }
  char caption[160];
  std::snprintf(
      caption, sizeof caption, "%s: %d features, %d tracked, %d with lidar depth, match %.0f %%",
      std::string(vision::to_string(frame.mode)).c_str(), frame.counts.features,
      frame.counts.ransac_inliers, frame.counts.depth_associated,
      100.0 * (std::isnan(frame.counts.match_success_rate()) ? 0.0
                                                             : frame.counts.match_success_rate()));
  label(features, caption);
  const auto q = [](const vision::ImageQuality& quality, const char* name) {
    char text[96];
    if (!quality.valid) {
      std::snprintf(text, sizeof text, "%s", name);
    } else {
      std::snprintf(text, sizeof text, "%s  g %.2f  sigma %.1f  conf %.2f", name,
                    quality.gradient_metric, quality.noise_sigma, quality.confidence);
    }
    return std::string(text);
  };
  cv::Mat top, bottom, mosaic;
  cv::hconcat(
      panel(frontend.visible_grey(), size, q(frame.quality.visible, "visible (enhanced)")),
      panel(frontend.thermal_grey(), size, q(frame.quality.thermal, "thermal (registered)")), top);
  cv::hconcat(panel(frontend.fused_grey(), size, q(frame.quality.fused, "DWT fusion")), features,
              bottom);
  cv::vconcat(top, bottom, mosaic);
  std::error_code ec;
  std::filesystem::create_directories(options_.directory, ec);
  char name[64];
  std::snprintf(name, sizeof name, "%s_%05llu.png",
                std::string(vision::to_string(frame.mode)).c_str(),
                static_cast<unsigned long long>(index));
  const std::string path = (std::filesystem::path(options_.directory) / name).string();
  if (!cv::imwrite(path, mosaic)) {
    if (error_.empty()) error_ = "cannot write " + path;
    return;
  }
  ++saved_[m];
  written_.push_back(path);
}

}  // namespace posed::posectl
