#include "tools/sim/smoke.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace posed::sim {

double SmokeSchedule::extinction_per_m(double t_s) const {
  if (!any() || t_s <= start_s || t_s >= clear_s) return 0.0;
  const auto smoothstep = [](double a, double b, double t) {
    if (b <= a) return t >= a ? 1.0 : 0.0;
    const double u = std::clamp((t - a) / (b - a), 0.0, 1.0);
    return u * u * (3 - 2 * u);
  };
  const double rise = smoothstep(start_s, dense_from_s, t_s);
  const double fall = 1.0 - smoothstep(dense_to_s, clear_s, t_s);
  return dense_extinction_per_m * std::min(rise, fall);
}

double headlight_backscatter(double sigma) {
  if (!(sigma > 0)) return 0.0;
  // With s = tan θ, ds / (1 + s²) = dθ: σ ∫₀^{π/2} exp(-2σ tan θ) dθ, a smooth bounded
  // integrand, by Simpson's rule (512 steps: within 1e-6 for σ up to 30 /m).
  constexpr int kSteps = 512;  // even
  const double h = 0.5 * std::numbers::pi / kSteps;
  const auto f = [&](int k) { return k == kSteps ? 0.0 : std::exp(-2 * sigma * std::tan(k * h)); };
  double sum = f(0) + f(kSteps);
  for (int k = 1; k < kSteps; ++k) sum += (k % 2 == 1 ? 4 : 2) * f(k);
  return sigma * sum * h / 3;
}

}  // namespace posed::sim
