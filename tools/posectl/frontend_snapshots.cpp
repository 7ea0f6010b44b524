#include "tools/posectl/frontend_snapshots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/vision/feature_overlay.hpp"

namespace posed::posectl {

namespace {

/// A grey panel in colour with a caption; black when the mode did not build the image.
cv::Mat panel(const cv::Mat& grey, const cv::Size& size, const std::string& caption) {
  cv::Mat out(size, CV_8UC3, cv::Scalar(0, 0, 0));
  if (!grey.empty()) {
    cv::Mat bgr;
    cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
    if (bgr.size() != size) cv::resize(bgr, bgr, size);
    bgr.copyTo(out);
  }
  if (!caption.empty()) vision::draw_label(out, caption);
  return out;
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
  const cv::Mat features = vision::feature_overlay(tracked, frame);
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
