#pragma once
// 16 -> 8-bit normalisation of raw thermal counts (seed 000 §2.1.1 step 0; seed 002 background
// 5: radiometric frames are 14/16-bit with low contrast). A linear stretch between two percentiles
// of the counts instead of the min-max stretch: a few hot or dead pixels (a lamp, the sun, a
// defective element) would otherwise squeeze the scene into a handful of grey levels. The stretch
// never spans fewer than `min_span_counts`, so a flat scene's noise is not blown up to full range.

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

namespace posed::vision {

struct ThermalNormalizeConfig {
  double low_percentile = 0.01;   ///< counts at or below this fraction map to 0 [0..1]
  double high_percentile = 0.99;  ///< counts at or above this fraction map to 255 [0..1]
  int min_span_counts = 48;       ///< narrowest stretch [counts]
};

struct ThermalNormalizeStats {
  std::uint16_t low_counts = 0;   ///< maps to grey 0 [counts]
  std::uint16_t high_counts = 0;  ///< maps to grey 255 [counts]
  std::uint32_t pixels = 0;       ///< pixels that entered the histogram [1]
};

class ThermalNormalizer {
 public:
  explicit ThermalNormalizer(const ThermalNormalizeConfig& config);

  /// `counts` (CV_16UC1) -> `grey` (CV_8UC1). The percentiles come from the pixels where `valid`
  /// (CV_8UC1, non-zero) is set, or from all pixels when `valid` is empty.
  ThermalNormalizeStats normalize(const cv::Mat& counts, const cv::Mat& valid, cv::Mat& grey);

 private:
  ThermalNormalizeConfig config_;
  std::vector<std::uint32_t> histogram_;
  std::vector<std::uint8_t> lut_;
};

}  // namespace posed::vision
