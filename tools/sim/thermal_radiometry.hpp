#pragma once
// Raw counts of a radiometric microbolometer against scene temperature, for the PLUG 617's
// 16-bit output. A bolometer's counts are linear in the in-band radiance it receives, and that
// radiance follows Planck's law in temperature; radiometric cameras publish the fit as
//   counts(T) = R1 / (R2 · (exp(B / T) − F)) − O        T in kelvin
// (FLIR's Planck constants, the model the exif of shared/realdata/thermal_16bit carries). The
// PLUG 617's own constants are not published; the defaults are that real camera's (R1 364058,
// R2 1, B 1428 K, F 1, O −228). Through them the real frame (counts 2623..2739, median 2699)
// reads 10.7..13.4 °C, a November afternoon outdoors; a 12 °C scene is 2678 counts, ~43
// counts/K there (so NETD 50 mK is ~2 counts; 25 counts/K at −30 °C, 71 at 70 °C), and
// −60..150 °C stays within the sensor's 14 bits (677..13131).

#include <cstdint>
#include <vector>

namespace posed::sim {

struct RadiometricCalibration {
  double r1 = 364058.0;  ///< Planck R1 [counts]
  double r2 = 1.0;       ///< Planck R2 [-]
  double b_k = 1428.0;   ///< Planck B [K]
  double f = 1.0;        ///< Planck F [-]
  double o = -228.0;     ///< Planck O, offset [counts]
};

class Radiometry {
 public:
  explicit Radiometry(const RadiometricCalibration& calibration = {});

  /// Counts a pixel reads for a scene at `temperature_c` [°C], exact and unrounded [counts].
  double counts(double temperature_c) const;
  /// The scene temperature of a count value (the inverse of counts()) [°C].
  double temperature_c(double counts) const;
  /// counts() rounded to the sensor's 14 bits, from a table (per pixel: no exp() call); within
  /// 0.01 counts of counts() over the table's range, clamped outside it.
  std::uint16_t counts_u14(float temperature_c) const {
    const float x = (temperature_c - kTableMinC) * kStepsPerK;
    if (!(x > 0.0f)) return raw_clamp(table_.front());
    const auto i = static_cast<std::size_t>(x);
    if (i + 1 >= table_.size()) return raw_clamp(table_.back());
    const float w = x - static_cast<float>(i);
    return raw_clamp(table_[i] + w * (table_[i + 1] - table_[i]));
  }

  /// the table's span [°C] and resolution [1/K]
  static constexpr float kTableMinC = -90.0f, kTableMaxC = 260.0f, kStepsPerK = 16.0f;
  /// the largest count a 14-bit sensor reports
  static constexpr std::uint16_t kMaxCounts = 16383;

 private:
  static std::uint16_t raw_clamp(float counts) {
    return counts <= 0.0f                             ? 0
           : counts >= static_cast<float>(kMaxCounts) ? kMaxCounts
                                                      : static_cast<std::uint16_t>(counts + 0.5f);
  }

  RadiometricCalibration calibration_;
  std::vector<float> table_;
};

}  // namespace posed::sim
