#include "core/vision/patch_shape.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>

namespace posed::vision {

Eigen::Matrix2d patch_shape(const cv::Mat& grey, cv::Point2f at, int half_px) {
  CV_Assert(grey.type() == CV_8UC1);
  const int x0 = std::max(1, static_cast<int>(std::lround(at.x)) - half_px);
  const int x1 = std::min(grey.cols - 2, static_cast<int>(std::lround(at.x)) + half_px);
  const int y0 = std::max(1, static_cast<int>(std::lround(at.y)) - half_px);
  const int y1 = std::min(grey.rows - 2, static_cast<int>(std::lround(at.y)) + half_px);
  double xx = 0, xy = 0, yy = 0;
  for (int y = y0; y <= y1; ++y) {
    const std::uint8_t* up = grey.ptr<std::uint8_t>(y - 1);
    const std::uint8_t* row = grey.ptr<std::uint8_t>(y);
    const std::uint8_t* down = grey.ptr<std::uint8_t>(y + 1);
    for (int x = x0; x <= x1; ++x) {
      const double gx = 0.5 * (static_cast<double>(row[x + 1]) - static_cast<double>(row[x - 1]));
      const double gy = 0.5 * (static_cast<double>(down[x]) - static_cast<double>(up[x]));
      xx += gx * gx;
      xy += gx * gy;
      yy += gy * gy;
    }
  }
  Eigen::Matrix2d G;
  G << xx, xy, xy, yy;
  // The largest eigenvalue of a symmetric 2x2.
  const double largest = 0.5 * (xx + yy) + std::sqrt(0.25 * (xx - yy) * (xx - yy) + xy * xy);
  if (!(largest > 0)) return Eigen::Matrix2d::Identity();
  return G / largest;
}

}  // namespace posed::vision
