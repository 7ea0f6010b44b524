#pragma once
// Visible + thermal fusion of seed 000 §2.1.2 (Fig. 8): both images through a 2-level 2-D DWT,
// the low band averaged (eq. 7), each detail coefficient taken from the image where it is larger
// in magnitude (eq. 8), and the inverse transform.
//
// Eq. (8) as printed, max(|C_I|, |C_V|), would rectify every detail coefficient (all edges would
// turn one-signed and the reconstruction would ring); the rule it names, "absolute-value maximum",
// and the one implemented here, keeps the chosen coefficient with its sign.

#include <opencv2/core/mat.hpp>

#include "core/vision/dwt.hpp"

namespace posed::vision {

struct FusionConfig {
  Wavelet wavelet = Wavelet::kLeGall53;  ///< see dwt.hpp for the choice
  int levels = 2;                        ///< seed 000: two levels suffice
  double thermal_low_weight = 0.5;       ///< weight of the thermal low band, eq. (7): 0.5
};

/// Eq. (7): out = w_t thermal + (1 - w_t) visible, element-wise (CV_32FC1, same size).
void fuse_low_band(const cv::Mat& visible, const cv::Mat& thermal, double thermal_weight,
                   cv::Mat& out);

/// Eq. (8): out = the one of visible, thermal with the larger magnitude, sign kept; ties go to
/// the visible coefficient (CV_32FC1, same size; out may alias either input).
void fuse_high_band(const cv::Mat& visible, const cv::Mat& thermal, cv::Mat& out);

class DwtFusion {
 public:
  explicit DwtFusion(const FusionConfig& config);

  /// Fuses two registered grey images (CV_8UC1, same size; any size, padded internally by edge
  /// replication) into `fused` (CV_8UC1).
  void fuse(const cv::Mat& visible, const cv::Mat& thermal, cv::Mat& fused);

  const FusionConfig& config() const { return config_; }

 private:
  FusionConfig config_;
  Dwt2d dwt_;
  cv::Mat padded_visible_, padded_thermal_;
  cv::Mat coeffs_visible_, coeffs_thermal_, reconstructed_;
};

}  // namespace posed::vision
