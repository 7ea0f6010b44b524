#pragma once
// Visible + thermal fusion of seed 000 §2.1.2 (Fig. 8): both images through a 2-level 2-D DWT,
// the low band averaged (eq. 7), each detail coefficient taken from the image where it is larger
// in magnitude (eq. 8), and the inverse transform.
//
// Eq. (8) as printed, max(|C_I|, |C_V|), would rectify every detail coefficient (all edges would
// turn one-signed and the reconstruction would ring); the rule it names, "absolute-value maximum",
// and the one implemented here, keeps the chosen coefficient with its sign.
//
// Noise-aware details (our change, on by default): eq. (8) compares raw magnitudes, so in flat
// regions, where both images hold only noise, it picks whichever image is noisier and the fusion
// inherits the worse noise of the two (a night-time visible image after seed 001's gamma and
// CLAHE easily has 5x the thermal noise). With the images' noise levels sigma_v, sigma_t (seed
// 002's noise metric) a detail coefficient counts as signal when it exceeds `significance` times
// its image's sigma: where either image has signal, the one with more signal in units of its own
// noise wins (|C_t| / sigma_t against |C_v| / sigma_v); where neither has, the quieter image's
// coefficient is kept. Both images go through the same transform, so a band's noise scales with
// its image's sigma and the one ratio serves every band.
//
// Noise-adaptive pre-smoothing (our change, `denoise`, on by default): a night-time visible image
// after gamma and CLAHE carries sigma_n of 10-20 grey, and whatever detail of it wins the selection
// brings that noise into the tracker's patches. Each stream noisier than `denoise_target_sigma` is
// smoothed by a Gaussian just wide enough to bring its white noise down to the target (a 2-D
// Gaussian of sigma s px scales white noise by sum_i k_i^2 over its 1-D taps, ~1 / (2 sqrt(pi) s)),
// at most `denoise_max_sigma_px`; the fusion then compares the residual noise levels.

#include <opencv2/core/mat.hpp>

#include "core/vision/dwt.hpp"

namespace posed::vision {

struct FusionConfig {
  Wavelet wavelet = Wavelet::kHaar;   ///< see dwt.hpp for the choice
  int levels = 2;                     ///< seed 000: two levels suffice
  double thermal_low_weight = 0.5;    ///< weight of the thermal low band, eq. (7): 0.5
  bool noise_weighted = true;         ///< details by significance (above); false: eq. (8)
  double significance = 3.0;          ///< a detail is signal above this x its sigma [-]
  bool denoise = true;                ///< noise-adaptive Gaussian pre-smoothing (above)
  double denoise_target_sigma = 2.0;  ///< smooth a stream's noise down to this [grey]
  double denoise_max_sigma_px = 3.0;  ///< widest Gaussian used [px]
};

/// Smooths `grey` (CV_8UC1) by the Gaussian that brings white noise of `noise_sigma` [grey] down
/// to `target_sigma` (no wider than `max_sigma_px`) into `out`, and returns the residual noise
/// sigma [grey]. Returns `noise_sigma` and leaves `out` a shallow copy of `grey` when the noise
/// is already at or below the target (or unknown: not positive).
double denoise_gaussian(const cv::Mat& grey, double noise_sigma, double target_sigma,
                        double max_sigma_px, cv::Mat& out);

/// Eq. (7): out = w_t thermal + (1 - w_t) visible, element-wise (CV_32FC1, same size).
void fuse_low_band(const cv::Mat& visible, const cv::Mat& thermal, double thermal_weight,
                   cv::Mat& out);

/// Eq. (8): out = the one of visible, thermal with the larger magnitude, sign kept; ties go to
/// the visible coefficient (CV_32FC1, same size; out may alias either input).
void fuse_high_band(const cv::Mat& visible, const cv::Mat& thermal, cv::Mat& out);

/// The noise-aware rule above, with each image's noise sigma (> 0) [grey].
void fuse_high_band_noise_aware(const cv::Mat& visible, const cv::Mat& thermal,
                                double visible_sigma, double thermal_sigma, double significance,
                                cv::Mat& out);

class DwtFusion {
 public:
  explicit DwtFusion(const FusionConfig& config);

  /// Fuses two registered grey images (CV_8UC1, same size; any size, padded internally by edge
  /// replication) into `fused` (CV_8UC1). `visible_noise`, `thermal_noise`: each image's noise
  /// sigma [grey] for the noise-aware rule; eq. (8) when either is not positive or the rule is
  /// off.
  void fuse(const cv::Mat& visible, const cv::Mat& thermal, cv::Mat& fused,
            double visible_noise = 0.0, double thermal_noise = 0.0);

  const FusionConfig& config() const { return config_; }

 private:
  FusionConfig config_;
  Dwt2d dwt_;
  cv::Mat padded_visible_, padded_thermal_;
  cv::Mat coeffs_visible_, coeffs_thermal_, reconstructed_;
};

}  // namespace posed::vision
