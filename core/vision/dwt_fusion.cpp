#include "core/vision/dwt_fusion.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace posed::vision {

void fuse_low_band(const cv::Mat& visible, const cv::Mat& thermal, double thermal_weight,
                   cv::Mat& out) {
  CV_Assert(visible.type() == CV_32FC1 && thermal.type() == CV_32FC1);
  CV_Assert(visible.size() == thermal.size());
  out.create(visible.size(), CV_32FC1);
  const float wt = static_cast<float>(thermal_weight), wv = 1.f - wt;
  for (int r = 0; r < visible.rows; ++r) {
    const float* v = visible.ptr<float>(r);
    const float* t = thermal.ptr<float>(r);
    float* o = out.ptr<float>(r);
    for (int c = 0; c < visible.cols; ++c) o[c] = wv * v[c] + wt * t[c];
  }
}

void fuse_high_band(const cv::Mat& visible, const cv::Mat& thermal, cv::Mat& out) {
  CV_Assert(visible.type() == CV_32FC1 && thermal.type() == CV_32FC1);
  CV_Assert(visible.size() == thermal.size());
  out.create(visible.size(), CV_32FC1);
  for (int r = 0; r < visible.rows; ++r) {
    const float* v = visible.ptr<float>(r);
    const float* t = thermal.ptr<float>(r);
    float* o = out.ptr<float>(r);
    for (int c = 0; c < visible.cols; ++c) o[c] = std::fabs(t[c]) > std::fabs(v[c]) ? t[c] : v[c];
  }
}

void fuse_high_band_noise_aware(const cv::Mat& visible, const cv::Mat& thermal,
                                double visible_sigma, double thermal_sigma, double significance,
                                cv::Mat& out) {
  CV_Assert(visible.type() == CV_32FC1 && thermal.type() == CV_32FC1);
  CV_Assert(visible.size() == thermal.size() && visible_sigma > 0 && thermal_sigma > 0);
  out.create(visible.size(), CV_32FC1);
  const float wv = static_cast<float>(1.0 / visible_sigma);
  const float wt = static_cast<float>(1.0 / thermal_sigma);
  const float k = static_cast<float>(significance);
  const bool thermal_quieter = thermal_sigma < visible_sigma;
  for (int r = 0; r < visible.rows; ++r) {
    const float* v = visible.ptr<float>(r);
    const float* t = thermal.ptr<float>(r);
    float* o = out.ptr<float>(r);
    for (int c = 0; c < visible.cols; ++c) {
      const float sv = wv * std::fabs(v[c]), st = wt * std::fabs(t[c]);  // in sigmas
      const bool signal = (sv > k) | (st > k);
      const bool take_thermal = signal ? st > sv : thermal_quieter;
      o[c] = take_thermal ? t[c] : v[c];
    }
  }
}

double denoise_gaussian(const cv::Mat& grey, double noise_sigma, double target_sigma,
                        double max_sigma_px, cv::Mat& out) {
  CV_Assert(grey.type() == CV_8UC1);
  if (!(noise_sigma > target_sigma) || !(target_sigma > 0) || !(max_sigma_px > 0)) {
    out = grey;
    return noise_sigma;
  }
  // Continuous approximation for the width, the discrete kernel for the residual.
  constexpr double kTwoSqrtPi = 3.5449077018110318;
  const double sigma_px = std::min(max_sigma_px, noise_sigma / (kTwoSqrtPi * target_sigma));
  const int ksize = 2 * static_cast<int>(std::ceil(3.0 * sigma_px)) + 1;
  const cv::Mat taps = cv::getGaussianKernel(ksize, sigma_px, CV_64F);
  const double gain = taps.dot(taps);  // 2-D: (sum k_i^2)^2 in variance, its root in sigma
  cv::GaussianBlur(grey, out, cv::Size(ksize, ksize), sigma_px, sigma_px, cv::BORDER_REPLICATE);
  return noise_sigma * gain;
}

DwtFusion::DwtFusion(const FusionConfig& config)
    : config_(config), dwt_(config.wavelet, config.levels) {}

void DwtFusion::fuse(const cv::Mat& visible, const cv::Mat& thermal, cv::Mat& fused,
                     double visible_noise, double thermal_noise) {
  CV_Assert(visible.type() == CV_8UC1 && thermal.type() == CV_8UC1);
  CV_Assert(visible.size() == thermal.size());
  const cv::Size padded = dwt_.padded_size(visible.size());
  const bool pad = padded != visible.size();
  const auto padded_view = [&](const cv::Mat& in, cv::Mat& storage) -> const cv::Mat& {
    if (!pad) return in;
    cv::copyMakeBorder(in, storage, 0, padded.height - in.rows, 0, padded.width - in.cols,
                       cv::BORDER_REPLICATE);
    return storage;
  };
  dwt_.forward(padded_view(visible, padded_visible_), coeffs_visible_);
  dwt_.forward(padded_view(thermal, padded_thermal_), coeffs_thermal_);

  // The coarsest low band is averaged (eq. 7) first; every other coefficient is a detail
  // coefficient of some level and takes the absolute maximum (eq. 8, or its noise-aware form). The
  // low band is the top-left corner, so the details are the rows beside it and every row below it.
  const cv::Rect low = Dwt2d::band_rect(padded, dwt_.levels(), Band::kLL);
  cv::Mat low_v = coeffs_visible_(low);
  fuse_low_band(low_v, coeffs_thermal_(low), config_.thermal_low_weight, low_v);
  const cv::Rect beside(low.width, 0, padded.width - low.width, low.height);
  const cv::Rect below(0, low.height, padded.width, padded.height - low.height);
  const bool noise_aware = config_.noise_weighted && visible_noise > 0 && thermal_noise > 0;
  for (const cv::Rect& rect : {beside, below}) {
    cv::Mat v = coeffs_visible_(rect);
    if (noise_aware) {
      fuse_high_band_noise_aware(v, coeffs_thermal_(rect), visible_noise, thermal_noise,
                                 config_.significance, v);
    } else {
      fuse_high_band(v, coeffs_thermal_(rect), v);
    }
  }
  dwt_.inverse(coeffs_visible_, reconstructed_);
  const cv::Mat cropped = reconstructed_(cv::Rect(0, 0, visible.cols, visible.rows));
  cropped.convertTo(fused, CV_8U);  // rounds and saturates
}

}  // namespace posed::vision
