#include "core/vision/corner_selection.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <utility>

namespace posed::vision {

void select_corners(cv::Mat& score, const cv::Mat& mask, int max_corners, double quality,
                    double min_distance_px, std::vector<cv::Point2f>& corners) {
  CV_Assert(score.type() == CV_32FC1);
  CV_Assert(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == score.size()));
  corners.clear();
  if (score.empty()) return;
  double max_score = 0;
  cv::minMaxLoc(score, nullptr, &max_score, nullptr, nullptr, mask);
  cv::threshold(score, score, max_score * quality, 0, cv::THRESH_TOZERO);
  cv::Mat dilated;
  cv::dilate(score, dilated, cv::Mat());

  // Local maxima inside the mask, one pixel in from the border.
  std::vector<const float*> candidates;
  for (int y = 1; y < score.rows - 1; ++y) {
    const float* s = score.ptr<float>(y);
    const float* d = dilated.ptr<float>(y);
    const std::uint8_t* m = mask.empty() ? nullptr : mask.ptr<std::uint8_t>(y);
    for (int x = 1; x < score.cols - 1; ++x) {
      const float value = s[x];
      if (value != 0 && value == d[x] && (m == nullptr || m[x] != 0)) candidates.push_back(s + x);
    }
  }
  if (candidates.empty()) return;
  // Strongest first; equal scores by address, so the order is fully determined.
  std::sort(candidates.begin(), candidates.end(), [](const float* a, const float* b) {
    return (*a > *b) ? true : (*a < *b) ? false : (a > b);
  });
  const auto pixel_of = [&](const float* p) {
    const auto offset = static_cast<std::size_t>(reinterpret_cast<const std::uint8_t*>(p) -
                                                 score.ptr<std::uint8_t>());
    const int y = static_cast<int>(offset / score.step);
    const int x =
        static_cast<int>((offset - static_cast<std::size_t>(y) * score.step) / sizeof(float));
    return cv::Point(x, y);
  };
  const auto full = [&] {
    return max_corners > 0 && static_cast<int>(corners.size()) == max_corners;
  };

  if (min_distance_px < 1) {
    for (const float* p : candidates) {
      const cv::Point q = pixel_of(p);
      corners.emplace_back(static_cast<float>(q.x), static_cast<float>(q.y));
      if (full()) break;
    }
    return;
  }
  // Cells of min_distance: a corner's rivals are in its cell and the eight around it.
  const int cell = cvRound(min_distance_px);
  const int grid_w = (score.cols + cell - 1) / cell;
  const int grid_h = (score.rows + cell - 1) / cell;
  std::vector<std::vector<cv::Point2f>> grid(static_cast<std::size_t>(grid_w) *
                                             static_cast<std::size_t>(grid_h));
  const double min_sq = min_distance_px * min_distance_px;
  for (const float* p : candidates) {
    const cv::Point q = pixel_of(p);
    const int cx = q.x / cell, cy = q.y / cell;
    bool good = true;
    for (int yy = std::max(0, cy - 1); good && yy <= std::min(grid_h - 1, cy + 1); ++yy) {
      for (int xx = std::max(0, cx - 1); good && xx <= std::min(grid_w - 1, cx + 1); ++xx) {
        for (const cv::Point2f& other : grid[static_cast<std::size_t>(yy * grid_w + xx)]) {
          const float dx = static_cast<float>(q.x) - other.x;
          const float dy = static_cast<float>(q.y) - other.y;
          if (dx * dx + dy * dy < min_sq) {
            good = false;
            break;
          }
        }
      }
    }
    if (!good) continue;
    const cv::Point2f corner(static_cast<float>(q.x), static_cast<float>(q.y));
    grid[static_cast<std::size_t>(cy * grid_w + cx)].push_back(corner);
    corners.push_back(corner);
    if (full()) break;
  }
}

float nth_smallest(const cv::Mat& values, std::size_t n) {
  CV_Assert(values.type() == CV_32FC1 && n < values.total());
  // A float's bits as an unsigned key in the floats' order: negative floats flipped whole,
  // positive ones with the sign bit set.
  const auto key_of = [](float f) {
    const auto bits = std::bit_cast<std::uint32_t>(f);
    return (bits & 0x80000000u) != 0 ? ~bits : bits | 0x80000000u;
  };
  std::uint32_t prefix = 0, prefix_mask = 0;
  std::size_t rank = n;  // among the values whose key starts with `prefix`
  std::array<std::uint32_t, 2048> count{};
  for (const auto& [shift, width] : {std::pair{21, 11}, std::pair{10, 11}, std::pair{0, 10}}) {
    const std::uint32_t digit_mask = (1u << width) - 1;
    std::fill(count.begin(), count.end(), 0u);
    for (int y = 0; y < values.rows; ++y) {
      const float* row = values.ptr<float>(y);
      for (int x = 0; x < values.cols; ++x) {
        const std::uint32_t key = key_of(row[x]);
        if ((key & prefix_mask) == prefix) ++count[(key >> shift) & digit_mask];
      }
    }
    std::uint32_t digit = 0;
    while (rank >= count[digit]) rank -= count[digit++];
    prefix |= digit << shift;
    prefix_mask |= digit_mask << shift;
  }
  const std::uint32_t bits = (prefix & 0x80000000u) != 0 ? prefix & 0x7fffffffu : ~prefix;
  return std::bit_cast<float>(bits);
}

}  // namespace posed::vision
