// LSD line features (seed 001): segments of a synthetic scene of rectangles are detected, keep
// their ids while the scene shifts, and stay on the shifted lines.

#include "core/vision/line_tracker.hpp"

#include <gtest/gtest.h>

#include <map>
#include <opencv2/imgproc.hpp>

#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::vision {
namespace {

/// Rectangles with anti-aliased edges on textured ground, shifted by (dx, dy) px.
cv::Mat rectangles(double dx, double dy) {
  cv::Mat image = scene::texture_image(640, 480, 0.01, 40, 60, 3, dx, dy, 2);
  cv::Mat layer(480 * 4, 640 * 4, CV_8UC1, cv::Scalar(0));
  const auto rect = [&](double x, double y, double w, double h) {
    cv::rectangle(layer,
                  cv::Rect(static_cast<int>(std::lround((x + dx) * 4)),
                           static_cast<int>(std::lround((y + dy) * 4)), static_cast<int>(w * 4),
                           static_cast<int>(h * 4)),
                  cv::Scalar(255), cv::FILLED);
  };
  rect(80, 60, 180, 120);
  rect(360, 90, 200, 150);
  rect(150, 280, 260, 140);
  cv::Mat small;
  cv::resize(layer, small, image.size(), 0, 0, cv::INTER_AREA);  // area sampling
  cv::Mat out;
  cv::addWeighted(image, 1.0, small, 0.5, 0.0, out);
  return out;
}

TEST(LineTracker, TracksSegmentsWithStableIds) {
  LineTracker tracker({});
  const cv::Point2f step(2.0f, 1.0f);
  std::map<std::uint64_t, std::pair<Eigen::Vector2f, Eigen::Vector2f>> first;  // id -> ends
  std::map<std::uint64_t, int> born;
  int continued = 0;
  for (int frame = 0; frame < 4; ++frame) {
    const float f = static_cast<float>(frame);
    const LineStats stats = tracker.track(rectangles(step.x * f, step.y * f));
    EXPECT_LE(stats.total, 50);
    if (frame == 0) {
      EXPECT_GE(stats.detected, 12);  // 3 rectangles x 4 sides
    } else {
      EXPECT_GE(stats.tracked, 12) << frame;
    }
    const Eigen::Vector2f shift(step.x * f, step.y * f);
    for (const LineFeature& l : tracker.lines()) {
      if (born.emplace(l.id, frame).second) {
        first[l.id] = {l.start_px - shift, l.end_px - shift};
        continue;
      }
      // The same segment: its end points stay on the shifted line (KLT on a straight edge is
      // constrained only across it, so along it the ends may slide).
      const auto& [a, b] = first[l.id];
      const Eigen::Vector2f d = (b - a).normalized(), n(-d.y(), d.x());
      EXPECT_LT(std::abs(n.dot(l.start_px - shift - a)), 0.5f) << l.id;  // across the line
      EXPECT_LT(std::abs(n.dot(l.end_px - shift - a)), 0.5f) << l.id;
      EXPECT_EQ(l.length, static_cast<std::uint32_t>(frame - born[l.id] + 1));
      ++continued;
    }
  }
  EXPECT_GT(continued, 30);
}

}  // namespace
}  // namespace posed::vision
