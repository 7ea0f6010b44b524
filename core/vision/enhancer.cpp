#include "core/vision/enhancer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace posed::vision {
namespace {

/// 1/V for V = 1..255; V = 0 (black, hue and saturation undefined, S = 0 by convention) maps
/// to grey V', which the callers handle.
const std::array<float, 256>& reciprocal_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    t[0] = 0.f;
    for (int v = 1; v < 256; ++v) t[static_cast<std::size_t>(v)] = 1.f / static_cast<float>(v);
    return t;
  }();
  return table;
}

}  // namespace

double adaptive_gamma(double mean_value, const EnhanceConfig& config) {
  // ln(mean) -> 0 for a white image and -> -inf for a black one: clamp before dividing.
  const double mean = std::clamp(mean_value, 1.0 / 255.0, 254.0 / 255.0);
  const double target = std::clamp(config.target_mean, 1.0 / 255.0, 254.0 / 255.0);
  return std::clamp(std::log(target) / std::log(mean), config.gamma_min, config.gamma_max);
}

Enhancer::Enhancer(const EnhanceConfig& config)
    : config_(config),
      clahe_(cv::createCLAHE(config.clahe_clip_limit, cv::Size(std::max(1, config.clahe_tiles_x),
                                                               std::max(1, config.clahe_tiles_y)))),
      lut_(1, 256, CV_8UC1) {}

EnhanceStats Enhancer::enhance_value(const cv::Mat& value, cv::Mat& value_out) {
  CV_Assert(value.type() == CV_8UC1);
  EnhanceStats stats;
  stats.mean_value = cv::mean(value)[0] / 255.0;
  const cv::Mat* current = &value;
  if (config_.adaptive_gamma) {
    stats.gamma = adaptive_gamma(stats.mean_value, config_);
    auto* lut = lut_.ptr<std::uint8_t>();
    for (int v = 0; v < 256; ++v) {
      lut[v] = cv::saturate_cast<std::uint8_t>(255.0 * std::pow(v / 255.0, stats.gamma));
    }
    cv::LUT(value, lut_, gamma_value_);
    current = &gamma_value_;
  }
  if (config_.clahe) {
    clahe_->apply(*current, value_out);
  } else if (current != &value_out) {
    current->copyTo(value_out);
  }
  return stats;
}

void Enhancer::value_of(const cv::Mat& colour) {
  cv::split(colour, channels_);
  cv::max(channels_[0], channels_[1], value_);
  cv::max(value_, channels_[2], value_);
}

EnhanceStats Enhancer::enhance_to_grey(const cv::Mat& image, bool rgb, cv::Mat& grey_out) {
  CV_Assert(image.type() == CV_8UC1 || image.type() == CV_8UC3);
  if (image.type() == CV_8UC1) {
    if (config_.enabled) return enhance_value(image, grey_out);
    image.copyTo(grey_out);
    return {};
  }
  cv::cvtColor(image, luminance_, rgb ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
  if (!config_.enabled) {
    luminance_.copyTo(grey_out);
    return {};
  }
  value_of(image);
  const EnhanceStats stats = enhance_value(value_, enhanced_value_);
  grey_out.create(image.size(), CV_8UC1);
  const auto& reciprocal = reciprocal_table();
  for (int r = 0; r < image.rows; ++r) {
    const std::uint8_t* y = luminance_.ptr<std::uint8_t>(r);
    const std::uint8_t* v = value_.ptr<std::uint8_t>(r);
    const std::uint8_t* v2 = enhanced_value_.ptr<std::uint8_t>(r);
    std::uint8_t* out = grey_out.ptr<std::uint8_t>(r);
    for (int c = 0; c < image.cols; ++c) {
      // Y <= V, so Y V'/V <= V' <= 255. A black pixel (V = 0) is grey: it becomes V'.
      const float scaled = static_cast<float>(y[c]) * static_cast<float>(v2[c]) * reciprocal[v[c]];
      out[c] = v[c] == 0 ? v2[c] : static_cast<std::uint8_t>(std::min(scaled + 0.5f, 255.f));
    }
  }
  return stats;
}

EnhanceStats Enhancer::enhance_colour(const cv::Mat& colour, cv::Mat& colour_out) {
  CV_Assert(colour.type() == CV_8UC3);
  if (!config_.enabled) {
    colour.copyTo(colour_out);
    return {};
  }
  value_of(colour);
  const EnhanceStats stats = enhance_value(value_, enhanced_value_);
  colour_out.create(colour.size(), CV_8UC3);
  const auto& reciprocal = reciprocal_table();
  for (int r = 0; r < colour.rows; ++r) {
    const std::uint8_t* in = colour.ptr<std::uint8_t>(r);
    const std::uint8_t* v = value_.ptr<std::uint8_t>(r);
    const std::uint8_t* v2 = enhanced_value_.ptr<std::uint8_t>(r);
    std::uint8_t* out = colour_out.ptr<std::uint8_t>(r);
    for (int c = 0; c < colour.cols; ++c) {
      const float ratio = static_cast<float>(v2[c]) * reciprocal[v[c]];
      for (int k = 0; k < 3; ++k) {
        const int i = 3 * c + k;
        // Every channel <= V, so channel V'/V <= V'. Black becomes grey V' (S = 0).
        out[i] = v[c] == 0 ? v2[c]
                           : static_cast<std::uint8_t>(
                                 std::min(static_cast<float>(in[i]) * ratio + 0.5f, 255.f));
      }
    }
  }
  return stats;
}

}  // namespace posed::vision
