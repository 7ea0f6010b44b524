#pragma once
// Low-light enhancement of seed 001 (§ image preprocessing, Fig. 2): the image goes to HSV, the
// brightness V alone gets an adaptive gamma correction and then CLAHE (contrast limited adaptive
// histogram equalisation), and H, S and the new V go back to colour.
//
// Two exact shortcuts instead of cv::cvtColor to HSV and back:
//  - With H and S unchanged, HSV -> BGR is linear in V (every channel is V times a function of H
//    and S), so the enhanced colour is the input scaled by V'/V per pixel. This is exact, where
//    8-bit HSV would quantise hue to 180 levels and cost two colour conversions.
//  - The tracker needs grey, and luminance Y is linear in B, G, R, so the grey of the enhanced
//    image is Y V'/V: `enhance_to_grey` never builds the enhanced colour image at all.
//
// Adaptive gamma: the text of seed 001 cites its gamma correction ([20-21]) without giving the
// formula. We use the mean-brightness gamma that maps the mean of V to `target_mean`:
//   V' = 255 (V/255)^gamma,   gamma = clamp(ln(target_mean) / ln(mean(V)/255), gamma_min,
//   gamma_max)
// which lifts dark images (gamma < 1, strongest in the shadows) and tones down bright ones, the
// behaviour seed 001 describes (Fig. 6). The clamp keeps a nearly black frame from turning its
// sensor noise into texture.

#include <opencv2/core/mat.hpp>
#include <opencv2/imgproc.hpp>

namespace posed::vision {

struct EnhanceConfig {
  bool enabled = true;            ///< off: the stream is only converted to grey
  bool adaptive_gamma = true;     ///< gamma step on V
  double target_mean = 0.5;       ///< mean brightness the gamma aims for [0..1]
  double gamma_min = 0.3;         ///< strongest brightening allowed [-]
  double gamma_max = 2.0;         ///< strongest darkening allowed [-]
  bool clahe = true;              ///< CLAHE step on V
  double clahe_clip_limit = 2.0;  ///< histogram clip, in multiples of the uniform bin [-]
  int clahe_tiles_x = 8;          ///< tiles across [1]
  int clahe_tiles_y = 8;          ///< tiles down [1]
};

/// What the enhancement saw and did to one image.
struct EnhanceStats {
  double mean_value = 0;  ///< mean of V before enhancement [0..1]
  double gamma = 1;       ///< gamma applied (1 when off) [-]
};

/// The adaptive gamma for an image whose V has mean `mean_value` [0..1], clamped as configured.
double adaptive_gamma(double mean_value, const EnhanceConfig& config);

class Enhancer {
 public:
  explicit Enhancer(const EnhanceConfig& config);

  /// V (CV_8UC1) -> CLAHE(gamma(V)) into `value_out` (CV_8UC1).
  EnhanceStats enhance_value(const cv::Mat& value, cv::Mat& value_out);

  /// Grey (CV_8UC1) or colour (CV_8UC3, B,G,R order, or R,G,B when `rgb`) in; the grey (BT.601
  /// luminance) of the enhanced image out (CV_8UC1). When disabled: just the grey.
  EnhanceStats enhance_to_grey(const cv::Mat& image, bool rgb, cv::Mat& grey_out);

  /// Colour in, enhanced colour out (same channel order), for display and inspection.
  EnhanceStats enhance_colour(const cv::Mat& colour, cv::Mat& colour_out);

  const EnhanceConfig& config() const { return config_; }

 private:
  void value_of(const cv::Mat& colour);

  EnhanceConfig config_;
  cv::Ptr<cv::CLAHE> clahe_;
  cv::Mat lut_;
  cv::Mat channels_[3];
  cv::Mat value_, gamma_value_, enhanced_value_, luminance_;
};

}  // namespace posed::vision
