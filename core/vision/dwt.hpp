#pragma once
// 2-D discrete wavelet transform (seed 000 §2.1.2, Fig. 3): each level splits the current low
// band into LL, LH, HL, HH; the next level splits LL again. Coefficients are kept in the Mallat
// layout in one float image: level 1's detail bands fill the outer three quarters, level 2's the
// next ring in, the last LL the top-left corner.
//
// Seed 000 does not name its wavelet. Three are offered, all as lifting schemes (Daubechies &
// Sweldens 1998), which are exactly invertible in any arithmetic and run in place:
//   kHaar     (db1) orthonormal, 2 taps, the cheapest; the front end's default: it tracked best
//             of the three on both synthetic drives (docs/frontend.md), its low band being a plain
//             block mean that averages the noise down furthest;
//   kLeGall53 (CDF 5/3, JPEG 2000 lossless) symmetric, 5/3 taps, no block seams;
//   kCdf97    (CDF 9/7, JPEG 2000 lossy) smoothest, twice the lifting steps.
// Haar's two lifting steps and scaling run as one pass ((e + o)/sqrt 2, (o - e)/sqrt 2). The
// separable transform runs rows first, then columns; the column pass works on whole rows as
// vectors (o_i += a (e_i + e_i+1) for rows e, o), so both passes stream contiguous memory and
// the inner loops vectorise. Borders use whole-sample symmetric extension.

#include <opencv2/core/mat.hpp>
#include <string_view>
#include <vector>

namespace posed::vision {

enum class Wavelet { kHaar, kLeGall53, kCdf97 };
std::string_view to_string(Wavelet wavelet);

/// Detail bands named (horizontal filter, vertical filter): kHL is high-pass along x and
/// low-pass along y (vertical edges), top-right of its level's square.
enum class Band { kLL, kHL, kLH, kHH };

class Dwt2d {
 public:
  /// `levels` >= 1 decompositions.
  Dwt2d(Wavelet wavelet, int levels);

  /// `image` (CV_8UC1 or CV_32FC1; rows and columns divisible by 2^levels) -> `coeffs`
  /// (CV_32FC1, same size, Mallat layout).
  void forward(const cv::Mat& image, cv::Mat& coeffs);
  /// `coeffs` (CV_32FC1, Mallat layout) -> `image` (CV_32FC1, same size).
  void inverse(const cv::Mat& coeffs, cv::Mat& image);

  /// Where band `band` of level `level` (1 = finest) lies in a coefficient image of `size`.
  /// kLL is only a stored band at level == levels.
  static cv::Rect band_rect(cv::Size size, int level, Band band);

  /// Smallest multiple of 2^levels that is >= each side of `size` (how far callers must pad).
  cv::Size padded_size(cv::Size size) const;

  Wavelet wavelet() const { return wavelet_; }
  int levels() const { return levels_; }

 private:
  struct Step {
    float coefficient;
    bool predict;  ///< true: odd += c (even_i + even_i+1); false: even += c (odd_i-1 + odd_i)
  };
  void forward_rows(cv::Mat& a, int width, int height);
  void forward_columns(cv::Mat& a, int width, int height);
  void inverse_rows(cv::Mat& a, int width, int height);
  void inverse_columns(cv::Mat& a, int width, int height);

  Wavelet wavelet_;
  int levels_;
  std::vector<Step> steps_;
  float scale_low_ = 1.f;   ///< low band multiplied by this after the steps
  float scale_high_ = 1.f;  ///< high band multiplied by this after the steps
  std::vector<float> line_, even_, odd_;
  cv::Mat scratch_;
};

}  // namespace posed::vision
