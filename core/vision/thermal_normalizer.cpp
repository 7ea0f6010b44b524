#include "core/vision/thermal_normalizer.hpp"

#include <algorithm>
#include <cmath>

namespace posed::vision {

ThermalNormalizer::ThermalNormalizer(const ThermalNormalizeConfig& config)
    : config_(config), histogram_(65536), lut_(65536) {}

ThermalNormalizeStats ThermalNormalizer::normalize(const cv::Mat& counts, const cv::Mat& valid,
                                                   cv::Mat& grey) {
  CV_Assert(counts.type() == CV_16UC1);
  CV_Assert(valid.empty() || (valid.type() == CV_8UC1 && valid.size() == counts.size()));
  std::fill(histogram_.begin(), histogram_.end(), 0u);
  ThermalNormalizeStats stats;
  for (int r = 0; r < counts.rows; ++r) {
    const std::uint16_t* in = counts.ptr<std::uint16_t>(r);
    if (valid.empty()) {
      for (int c = 0; c < counts.cols; ++c) ++histogram_[in[c]];
    } else {
      const std::uint8_t* ok = valid.ptr<std::uint8_t>(r);
      for (int c = 0; c < counts.cols; ++c) histogram_[in[c]] += ok[c] != 0 ? 1u : 0u;
    }
  }
  std::uint64_t total = 0;
  for (const std::uint32_t h : histogram_) total += h;
  stats.pixels = static_cast<std::uint32_t>(total);
  grey.create(counts.size(), CV_8UC1);
  if (total == 0) {
    grey.setTo(0);
    return stats;
  }

  // The first count whose cumulative share reaches each percentile.
  const auto count_at = [&](double fraction) {
    const double want = std::clamp(fraction, 0.0, 1.0) * static_cast<double>(total);
    std::uint64_t cumulative = 0;
    for (std::size_t v = 0; v < histogram_.size(); ++v) {
      cumulative += histogram_[v];
      if (static_cast<double>(cumulative) >= want && cumulative > 0) return static_cast<int>(v);
    }
    return 65535;
  };
  int low = count_at(config_.low_percentile);
  int high = count_at(config_.high_percentile);
  const int min_span = std::clamp(config_.min_span_counts, 1, 65535);
  if (high - low < min_span) {  // widen around the middle, kept inside [0, 65535]
    const int middle = (low + high) / 2;
    low = std::clamp(middle - min_span / 2, 0, 65535 - min_span);
    high = low + min_span;
  }
  stats.low_counts = static_cast<std::uint16_t>(low);
  stats.high_counts = static_cast<std::uint16_t>(high);

  const double scale = 255.0 / static_cast<double>(high - low);
  std::fill(lut_.begin(), lut_.begin() + low, std::uint8_t{0});
  for (int v = low; v <= high; ++v) {
    lut_[static_cast<std::size_t>(v)] =
        static_cast<std::uint8_t>(std::lround(static_cast<double>(v - low) * scale));
  }
  std::fill(lut_.begin() + high + 1, lut_.end(), std::uint8_t{255});
  for (int r = 0; r < counts.rows; ++r) {
    const std::uint16_t* in = counts.ptr<std::uint16_t>(r);
    std::uint8_t* out = grey.ptr<std::uint8_t>(r);
    for (int c = 0; c < counts.cols; ++c) out[c] = lut_[in[c]];
  }
  return stats;
}

}  // namespace posed::vision
