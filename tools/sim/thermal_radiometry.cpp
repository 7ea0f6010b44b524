#include "tools/sim/thermal_radiometry.hpp"

#include <cmath>

namespace posed::sim {
namespace {
constexpr double kZeroCelsiusK = 273.15;
}

Radiometry::Radiometry(const RadiometricCalibration& calibration) : calibration_(calibration) {
  const auto n = static_cast<std::size_t>((kTableMaxC - kTableMinC) * kStepsPerK) + 1;
  table_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    table_[i] = static_cast<float>(counts(kTableMinC + static_cast<double>(i) / kStepsPerK));
}

double Radiometry::counts(double temperature_c) const {
  const RadiometricCalibration& c = calibration_;
  const double t_k = temperature_c + kZeroCelsiusK;
  return c.r1 / (c.r2 * (std::exp(c.b_k / t_k) - c.f)) - c.o;
}

double Radiometry::temperature_c(double counts) const {
  const RadiometricCalibration& c = calibration_;
  return c.b_k / std::log(c.r1 / (c.r2 * (counts + c.o)) + c.f) - kZeroCelsiusK;
}

}  // namespace posed::sim
