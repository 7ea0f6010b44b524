#pragma once
// Image quality of seed 002 (claims 7-14 and 33-36): a gradient metric g and a noise metric
// sigma_n per image, combined into the covariance weight omega (Sigma = omega Sigma_base) of the
// stream's visual factors and a confidence in (0, 1]. The formula images of the published text
// are missing from our copy; they are reconstructed from its definitions and the methods it
// builds on, as follows (docs/frontend.md discusses each).
//
// Gradient G of a pixel: |Sobel_x| + |Sobel_y|, divided by 8 so that a ramp of slope s grey/px
// along an axis has G = s [grey/px] (a step of h grey gives G = h/2 beside it). A pixel is an
// edge when G >= max(edge_gradient, edge_noise_factor sigma_n): a gradient the noise alone would
// make is not an edge (on white noise G exceeds 2.5 sigma at ~0.01 % of the pixels), so noise
// does not pass for texture.
//   g = ln(1 + lambda n_e / n_t) / ln(1 + lambda)               (n_e edges of n_t pixels)
// which is 0 without edges, 1 when every pixel is one, and rises faster for larger lambda (the
// patent's "rate" parameter; the log saturation follows Shim et al. 2014's gradient metric).
//
// Noise, Immerkaer (1996) on the pixels the patent's two operators keep:
//   M = [1 -2 1; -2 4 -2; 1 -2 1],
//   sigma_n = sqrt(pi/2) / (6 N_s) sum_i h(i) u(i) |I * M|(i),   N_s = sum_i h(i) u(i)
//   h(i) = 1 when G_i < sigma (homogeneous), u(i) = 1 when eps_l < I(i) < eps_u (unsaturated).
// The threshold sigma is chosen per image as the gradient below which `homogeneous_fraction` of
// the pixels lie (Tai & Yang 2008), so it adapts to the noise it is estimating instead of
// clipping it. Too few qualifying pixels (a black or blown-out frame): sigma_n is unknown and
// counts as `unknown_noise_sigma`.
//
// Immerkaer's estimator assumes white noise. Resampling correlates it and the estimate collapses
// (white noise of 6 grey upsampled 1.42x, as the thermal image is: true 4.0, estimated 1.2), and
// the noise then passes the edge threshold as texture. So images are assessed at their native
// resolution (VisualFrontend assesses the thermal stream on its raw frame), and an image built
// from resampled ones gets a lower bound (`min_noise_sigma`; for the fusion, the noisier source).
//
// Covariance weight and confidence:
//   omega = clamp(lambda_n (sigma_n + lambda_g (1 - g)), omega_min, omega_max)
//   confidence = omega_min / omega
// lambda_n sets omega's scale (the patent: to suit the IMU noise), lambda_g [grey] how much the
// gradient metric weighs against the noise (larger: more); confidence 1 is the best image the
// clamp allows.

#include <array>
#include <cstddef>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

namespace posed::vision {

struct QualityConfig {
  double edge_gradient = 4.0;         ///< least G at which a pixel is an edge [grey/px]
  double edge_noise_factor = 2.5;     ///< edges also need G >= this x sigma_n [-]
  double gradient_rate = 30.0;        ///< lambda of the gradient metric [-]
  double homogeneous_fraction = 0.9;  ///< share of pixels, lowest G first, that h() keeps [0..1]
  int saturation_low = 8;             ///< eps_l: u() keeps I > this [grey]
  int saturation_high = 247;          ///< eps_u: u() keeps I < this [grey]
  double min_noise_fraction = 0.02;   ///< fewer qualifying pixels than this share: unknown [-]
  double unknown_noise_sigma = 20.0;  ///< sigma_n assumed when unknown [grey]
  double lambda_n = 0.5;              ///< scale of omega [1/grey]
  double lambda_g = 4.0;              ///< weight of the gradient metric in omega [grey]
  double omega_min = 1.0;             ///< the best image's covariance scale [-]
  double omega_max = 100.0;           ///< the worst image's covariance scale [-]
  /// every row_step-th row is assessed (each with its two neighbours): the metrics are
  /// statistics over ~10^5 pixels, which half the rows estimate to well under 1 % [1]
  int row_step = 2;
};

struct ImageQuality {
  bool valid = false;               ///< an image was assessed
  double gradient_metric = 0;       ///< g [0..1]
  double edge_fraction = 0;         ///< n_e / n_t [0..1]
  double noise_sigma = 0;           ///< sigma_n (or unknown_noise_sigma) [grey]
  bool noise_known = false;         ///< enough homogeneous unsaturated pixels
  double homogeneous_gradient = 0;  ///< the threshold sigma of h() chosen [grey/px]
  double edge_threshold = 0;        ///< the edge threshold applied [grey/px]
  std::uint32_t pixels = 0;         ///< n_t, pixels assessed [1]
  std::uint32_t edge_pixels = 0;    ///< n_e [1]
  std::uint32_t noise_pixels = 0;   ///< N_s [1]
  double omega = 0;                 ///< covariance weight [-]
  double confidence = 0;            ///< omega_min / omega, (0..1]
};

/// omega and confidence from g and sigma_n (the last formulas above).
void weigh(const QualityConfig& config, ImageQuality& quality);

/// Gradient histogram resolution: G is binned in quarter grey/px up to 1020 / 4 = 255 grey/px.
inline constexpr std::size_t kGradientBins = 1024;
inline constexpr double kBinsPerGrey = 4.0;

class QualityAssessor {
 public:
  explicit QualityAssessor(const QualityConfig& config);

  /// Assesses a grey image (CV_8UC1, at least 3x3). `min_noise_sigma` [grey] bounds sigma_n
  /// from below: for an image whose noise is known to be at least that (see below).
  ImageQuality assess(const cv::Mat& grey, double min_noise_sigma = 0.0);

  const QualityConfig& config() const { return config_; }

 private:
  QualityConfig config_;
  // Per gradient bin (G in quarter grey/px, 0..1020): all pixels, unsaturated pixels, and the sum
  // of |I * M| over the unsaturated ones, so that the threshold of h() can be chosen after one
  // pass.
  std::array<std::uint32_t, kGradientBins> all_{}, unsaturated_{};
  std::array<std::uint64_t, kGradientBins> response_{};
  std::vector<std::uint16_t> gradient_row_;
  std::vector<std::uint16_t> response_row_;
};

}  // namespace posed::vision
