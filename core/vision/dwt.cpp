#include "core/vision/dwt.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace posed::vision {
namespace {

/// out[j] += c0 x0[j] + c1 x1[j]: the one kernel of every lifting step, along a row (x0, x1 the
/// neighbours) or down the columns (x0, x1 whole neighbouring rows).
inline void lift(float* __restrict out, const float* __restrict x0, const float* __restrict x1,
                 float c0, float c1, int n) {
  for (int j = 0; j < n; ++j) out[j] += c0 * x0[j] + c1 * x1[j];
}

inline void scale(float* __restrict x, float s, int n) {
  if (s == 1.f) return;
  for (int j = 0; j < n; ++j) x[j] *= s;
}

}  // namespace

std::string_view to_string(Wavelet wavelet) {
  switch (wavelet) {
    case Wavelet::kHaar:
      return "haar";
    case Wavelet::kLeGall53:
      return "legall53";
    case Wavelet::kCdf97:
      return "cdf97";
  }
  return "unknown";
}

Dwt2d::Dwt2d(Wavelet wavelet, int levels) : wavelet_(wavelet), levels_(std::max(1, levels)) {
  switch (wavelet) {
    case Wavelet::kHaar:
      // d = o - e; s = e + d/2 = (e + o)/2; orthonormal scaling.
      steps_ = {{-1.f, true}, {0.5f, false}};
      scale_low_ = std::sqrt(2.f);
      scale_high_ = 1.f / std::sqrt(2.f);
      break;
    case Wavelet::kLeGall53:
      // d = o - (e_i + e_i+1)/2; s = e + (d_i-1 + d_i)/4.
      steps_ = {{-0.5f, true}, {0.25f, false}};
      break;
    case Wavelet::kCdf97: {
      // Daubechies & Sweldens (1998) factorisation of the CDF 9/7 pair.
      constexpr float kAlpha = -1.586134342059924f, kBeta = -0.052980118572961f;
      constexpr float kGamma = 0.882911075530934f, kDelta = 0.443506852043971f;
      constexpr float kK = 1.230174104914001f;
      steps_ = {{kAlpha, true}, {kBeta, false}, {kGamma, true}, {kDelta, false}};
      scale_low_ = 1.f / kK;
      scale_high_ = kK;
      break;
    }
  }
}

cv::Size Dwt2d::padded_size(cv::Size size) const {
  const int m = 1 << levels_;
  return {(size.width + m - 1) / m * m, (size.height + m - 1) / m * m};
}

cv::Rect Dwt2d::band_rect(cv::Size size, int level, Band band) {
  const int w = size.width >> level, h = size.height >> level;
  switch (band) {
    case Band::kLL:
      return {0, 0, w, h};
    case Band::kHL:
      return {w, 0, w, h};
    case Band::kLH:
      return {0, h, w, h};
    case Band::kHH:
      return {w, h, w, h};
  }
  return {};
}

// Haar's steps use only one neighbour each (c1 = 0 for the predict, c0 = 0 for the update),
// which the same two-tap lifting expresses: predict o_i += c e_i (+ 0 e_i+1), update
// e_i += 0 o_i-1 + c o_i.
namespace {
struct Taps {
  float c0, c1;
};
Taps taps(Wavelet wavelet, float coefficient, bool predict) {
  if (wavelet == Wavelet::kHaar) return predict ? Taps{coefficient, 0.f} : Taps{0.f, coefficient};
  return {coefficient, coefficient};
}
}  // namespace

void Dwt2d::forward_rows(cv::Mat& a, int width, int height) {
  const int n = width / 2;
  even_.resize(static_cast<std::size_t>(n));
  odd_.resize(static_cast<std::size_t>(n));
  float* e = even_.data();
  float* o = odd_.data();
  if (wavelet_ == Wavelet::kHaar) {  // its two lifting steps and scaling in one pass
    constexpr float k = 0.70710678118654752f;
    for (int r = 0; r < height; ++r) {
      float* p = a.ptr<float>(r);
      for (int i = 0; i < n; ++i) {
        e[i] = (p[2 * i] + p[2 * i + 1]) * k;
        o[i] = (p[2 * i + 1] - p[2 * i]) * k;
      }
      std::memcpy(p, e, sizeof(float) * static_cast<std::size_t>(n));
      std::memcpy(p + n, o, sizeof(float) * static_cast<std::size_t>(n));
    }
    return;
  }
  for (int r = 0; r < height; ++r) {
    float* p = a.ptr<float>(r);
    for (int i = 0; i < n; ++i) {
      e[i] = p[2 * i];
      o[i] = p[2 * i + 1];
    }
    for (const Step& s : steps_) {
      const Taps t = taps(wavelet_, s.coefficient, s.predict);
      if (s.predict) {  // o_i += c0 e_i + c1 e_i+1, e_n = e_n-1 (symmetric extension)
        lift(o, e, e + 1, t.c0, t.c1, n - 1);
        o[n - 1] += (t.c0 + t.c1) * e[n - 1];
      } else {  // e_i += c0 o_i-1 + c1 o_i, o_-1 = o_0
        lift(e + 1, o, o + 1, t.c0, t.c1, n - 1);
        e[0] += (t.c0 + t.c1) * o[0];
      }
    }
    scale(e, scale_low_, n);
    scale(o, scale_high_, n);
    std::memcpy(p, e, sizeof(float) * static_cast<std::size_t>(n));
    std::memcpy(p + n, o, sizeof(float) * static_cast<std::size_t>(n));
  }
}

void Dwt2d::inverse_rows(cv::Mat& a, int width, int height) {
  const int n = width / 2;
  even_.resize(static_cast<std::size_t>(n));
  odd_.resize(static_cast<std::size_t>(n));
  float* e = even_.data();
  float* o = odd_.data();
  if (wavelet_ == Wavelet::kHaar) {
    constexpr float k = 0.70710678118654752f;
    for (int r = 0; r < height; ++r) {
      float* p = a.ptr<float>(r);
      std::memcpy(e, p, sizeof(float) * static_cast<std::size_t>(n));
      std::memcpy(o, p + n, sizeof(float) * static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i) {
        p[2 * i] = (e[i] - o[i]) * k;
        p[2 * i + 1] = (e[i] + o[i]) * k;
      }
    }
    return;
  }
  for (int r = 0; r < height; ++r) {
    float* p = a.ptr<float>(r);
    std::memcpy(e, p, sizeof(float) * static_cast<std::size_t>(n));
    std::memcpy(o, p + n, sizeof(float) * static_cast<std::size_t>(n));
    scale(e, 1.f / scale_low_, n);
    scale(o, 1.f / scale_high_, n);
    for (auto it = steps_.rbegin(); it != steps_.rend(); ++it) {
      const Taps t = taps(wavelet_, -it->coefficient, it->predict);
      if (it->predict) {
        lift(o, e, e + 1, t.c0, t.c1, n - 1);
        o[n - 1] += (t.c0 + t.c1) * e[n - 1];
      } else {
        lift(e + 1, o, o + 1, t.c0, t.c1, n - 1);
        e[0] += (t.c0 + t.c1) * o[0];
      }
    }
    for (int i = 0; i < n; ++i) {
      p[2 * i] = e[i];
      p[2 * i + 1] = o[i];
    }
  }
}

void Dwt2d::forward_columns(cv::Mat& a, int width, int height) {
  const int n = height / 2;
  const std::size_t row_bytes = sizeof(float) * static_cast<std::size_t>(width);
  if (wavelet_ == Wavelet::kHaar) {  // rows 2i, 2i+1 -> low row i, high row n+i
    constexpr float k = 0.70710678118654752f;
    for (int i = 0; i < n; ++i) {
      const float* __restrict r0 = a.ptr<float>(2 * i);
      const float* __restrict r1 = a.ptr<float>(2 * i + 1);
      float* __restrict lo = scratch_.ptr<float>(i);
      float* __restrict hi = scratch_.ptr<float>(n + i);
      for (int c = 0; c < width; ++c) {
        lo[c] = (r0[c] + r1[c]) * k;
        hi[c] = (r1[c] - r0[c]) * k;
      }
    }
    for (int r = 0; r < height; ++r) {
      std::memcpy(a.ptr<float>(r), scratch_.ptr<float>(r), row_bytes);
    }
    return;
  }
  // Even rows to the top half, odd rows to the bottom half; lifting on whole rows.
  for (int i = 0; i < n; ++i) {
    std::memcpy(scratch_.ptr<float>(i), a.ptr<float>(2 * i), row_bytes);
    std::memcpy(scratch_.ptr<float>(n + i), a.ptr<float>(2 * i + 1), row_bytes);
  }
  const auto e = [&](int i) { return scratch_.ptr<float>(i); };
  const auto o = [&](int i) { return scratch_.ptr<float>(n + i); };
  for (const Step& s : steps_) {
    const Taps t = taps(wavelet_, s.coefficient, s.predict);
    if (s.predict) {
      for (int i = 0; i < n - 1; ++i) lift(o(i), e(i), e(i + 1), t.c0, t.c1, width);
      lift(o(n - 1), e(n - 1), e(n - 1), t.c0, t.c1, width);
    } else {
      lift(e(0), o(0), o(0), t.c0, t.c1, width);
      for (int i = 1; i < n; ++i) lift(e(i), o(i - 1), o(i), t.c0, t.c1, width);
    }
  }
  for (int i = 0; i < n; ++i) {
    scale(e(i), scale_low_, width);
    scale(o(i), scale_high_, width);
  }
  for (int r = 0; r < height; ++r) std::memcpy(a.ptr<float>(r), scratch_.ptr<float>(r), row_bytes);
}

void Dwt2d::inverse_columns(cv::Mat& a, int width, int height) {
  const int n = height / 2;
  const std::size_t row_bytes = sizeof(float) * static_cast<std::size_t>(width);
  if (wavelet_ == Wavelet::kHaar) {
    constexpr float k = 0.70710678118654752f;
    for (int r = 0; r < height; ++r) {
      std::memcpy(scratch_.ptr<float>(r), a.ptr<float>(r), row_bytes);
    }
    for (int i = 0; i < n; ++i) {
      const float* __restrict lo = scratch_.ptr<float>(i);
      const float* __restrict hi = scratch_.ptr<float>(n + i);
      float* __restrict r0 = a.ptr<float>(2 * i);
      float* __restrict r1 = a.ptr<float>(2 * i + 1);
      for (int c = 0; c < width; ++c) {
        r0[c] = (lo[c] - hi[c]) * k;
        r1[c] = (lo[c] + hi[c]) * k;
      }
    }
    return;
  }
  for (int r = 0; r < height; ++r) std::memcpy(scratch_.ptr<float>(r), a.ptr<float>(r), row_bytes);
  const auto e = [&](int i) { return scratch_.ptr<float>(i); };
  const auto o = [&](int i) { return scratch_.ptr<float>(n + i); };
  for (int i = 0; i < n; ++i) {
    scale(e(i), 1.f / scale_low_, width);
    scale(o(i), 1.f / scale_high_, width);
  }
  for (auto it = steps_.rbegin(); it != steps_.rend(); ++it) {
    const Taps t = taps(wavelet_, -it->coefficient, it->predict);
    if (it->predict) {
      for (int i = 0; i < n - 1; ++i) lift(o(i), e(i), e(i + 1), t.c0, t.c1, width);
      lift(o(n - 1), e(n - 1), e(n - 1), t.c0, t.c1, width);
    } else {
      lift(e(0), o(0), o(0), t.c0, t.c1, width);
      for (int i = 1; i < n; ++i) lift(e(i), o(i - 1), o(i), t.c0, t.c1, width);
    }
  }
  for (int i = 0; i < n; ++i) {
    std::memcpy(a.ptr<float>(2 * i), e(i), row_bytes);
    std::memcpy(a.ptr<float>(2 * i + 1), o(i), row_bytes);
  }
}

void Dwt2d::forward(const cv::Mat& image, cv::Mat& coeffs) {
  CV_Assert(image.type() == CV_8UC1 || image.type() == CV_32FC1);
  CV_Assert(padded_size(image.size()) == image.size());
  image.convertTo(coeffs, CV_32F);
  scratch_.create(image.size(), CV_32FC1);
  int w = image.cols, h = image.rows;
  for (int level = 0; level < levels_; ++level) {
    forward_rows(coeffs, w, h);
    forward_columns(coeffs, w, h);
    w /= 2;
    h /= 2;
  }
}

void Dwt2d::inverse(const cv::Mat& coeffs, cv::Mat& image) {
  CV_Assert(coeffs.type() == CV_32FC1);
  CV_Assert(padded_size(coeffs.size()) == coeffs.size());
  if (&coeffs != &image) coeffs.copyTo(image);
  scratch_.create(coeffs.size(), CV_32FC1);
  for (int level = levels_ - 1; level >= 0; --level) {
    const int w = coeffs.cols >> level, h = coeffs.rows >> level;
    inverse_columns(image, w, h);
    inverse_rows(image, w, h);
  }
}

}  // namespace posed::vision
