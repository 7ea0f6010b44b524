#include "core/vision/image_quality.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>

namespace posed::vision {

void weigh(const QualityConfig& config, ImageQuality& quality) {
  const double omega =
      config.lambda_n * (quality.noise_sigma + config.lambda_g * (1.0 - quality.gradient_metric));
  quality.omega = std::clamp(omega, config.omega_min, config.omega_max);
  quality.confidence = config.omega_min / quality.omega;
}

QualityAssessor::QualityAssessor(const QualityConfig& config) : config_(config) {}

ImageQuality QualityAssessor::assess(const cv::Mat& grey, double min_noise_sigma) {
  CV_Assert(grey.type() == CV_8UC1 && grey.rows >= 3 && grey.cols >= 3);
  all_.fill(0);
  unsaturated_.fill(0);
  response_.fill(0);
  const int w = grey.cols, h = grey.rows;
  gradient_row_.resize(static_cast<std::size_t>(w));
  response_row_.resize(static_cast<std::size_t>(w));
  const int low = config_.saturation_low, high = config_.saturation_high;
  const int row_step = std::max(1, config_.row_step);
  std::uint64_t assessed = 0;
  for (int r = 1; r < h - 1; r += row_step) {
    assessed += static_cast<std::uint64_t>(w - 2);
    const std::uint8_t* up = grey.ptr<std::uint8_t>(r - 1);
    const std::uint8_t* mid = grey.ptr<std::uint8_t>(r);
    const std::uint8_t* down = grey.ptr<std::uint8_t>(r + 1);
    std::uint16_t* g = gradient_row_.data();
    std::uint16_t* m = response_row_.data();
    // Sobel and Immerkaer's mask in 16-bit integers, branch-free (vectorised); the histograms in
    // the scalar loop below.
    for (int c = 1; c < w - 1; ++c) {
      const int a = up[c - 1], b = up[c], d = up[c + 1];
      const int e = mid[c - 1], f = mid[c], k = mid[c + 1];
      const int p = down[c - 1], q = down[c], s = down[c + 1];
      const int sx = (d + 2 * k + s) - (a + 2 * e + p);
      const int sy = (p + 2 * q + s) - (a + 2 * b + d);
      // G in quarter grey/px: (|sx| + |sy|) / 8 * 4, at most 2040 / 2 = 1020 < kGradientBins.
      g[c] = static_cast<std::uint16_t>((std::abs(sx) + std::abs(sy)) >> 1);
      const int laplace = (a + d + p + s) - 2 * (b + e + k + q) + 4 * f;
      m[c] = static_cast<std::uint16_t>(std::abs(laplace));
    }
    for (int c = 1; c < w - 1; ++c) {
      const std::uint16_t gc = g[c];
      ++all_[gc];
      const int value = mid[c];
      if (value > low && value < high) {
        ++unsaturated_[gc];
        response_[gc] += m[c];
      }
    }
  }

  ImageQuality q;
  q.valid = true;
  q.pixels = static_cast<std::uint32_t>(assessed);
  // Noise first: the edge threshold depends on it. Threshold of h(): the smallest gradient bin
  // t with at least homogeneous_fraction of the pixels at G < t.
  const double want = std::clamp(config_.homogeneous_fraction, 0.0, 1.0) * q.pixels;
  std::uint64_t cumulative = 0, noise_pixels = 0, response_sum = 0;
  std::size_t threshold = 0;
  while (threshold < all_.size() && static_cast<double>(cumulative) < want) {
    cumulative += all_[threshold];
    noise_pixels += unsaturated_[threshold];
    response_sum += response_[threshold];
    ++threshold;
  }
  q.homogeneous_gradient = static_cast<double>(threshold) / kBinsPerGrey;
  q.noise_pixels = static_cast<std::uint32_t>(noise_pixels);
  q.noise_known = noise_pixels > 0 &&
                  static_cast<double>(noise_pixels) >= config_.min_noise_fraction * q.pixels;
  q.noise_sigma = q.noise_known
                      ? std::sqrt(std::numbers::pi / 2.0) * static_cast<double>(response_sum) /
                            (6.0 * static_cast<double>(noise_pixels))
                      : config_.unknown_noise_sigma;
  q.noise_sigma = std::max(q.noise_sigma, min_noise_sigma);

  // Edges: gradients above what the noise makes.
  q.edge_threshold =
      std::max(config_.edge_gradient,
               config_.edge_noise_factor * (q.noise_known ? q.noise_sigma : min_noise_sigma));
  const auto first_edge_bin = static_cast<std::size_t>(std::ceil(q.edge_threshold * kBinsPerGrey));
  for (std::size_t v = std::min(first_edge_bin, all_.size()); v < all_.size(); ++v) {
    q.edge_pixels += all_[v];
  }
  q.edge_fraction = static_cast<double>(q.edge_pixels) / q.pixels;
  const double lambda = std::max(1e-9, config_.gradient_rate);
  q.gradient_metric = std::log1p(lambda * q.edge_fraction) / std::log1p(lambda);
  weigh(config_, q);
  return q;
}

}  // namespace posed::vision
