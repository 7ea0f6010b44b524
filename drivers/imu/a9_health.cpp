#include "drivers/imu/a9_health.hpp"

#include <cmath>

namespace posed::drivers::a9 {

void A9HealthMonitor::update(const A9SensorFrame& frame) {
  bool saturated = false;
  for (std::size_t i = 0; i < 3; ++i) {
    saturated =
        saturated ||
        std::fabs(static_cast<double>(frame.gyro_radps[i])) >= config_.gyro_saturation_radps ||
        std::fabs(static_cast<double>(frame.accel_g[i])) >= config_.accel_saturation_g;
  }
  if (saturated) ++health_.saturated;

  if (health_.frames > 0) {
    // Modular difference: a 32-bit wrap is a normal forward step.
    const auto step = static_cast<std::int32_t>(frame.counter_us - health_.last_counter_us);
    if (step == 0) {
      ++health_.duplicate_counters;
    } else if (step < 0) {
      ++health_.backwards_counters;
    } else {
      const double nominal_us = 1e6 / config_.nominal_rate_hz;
      const auto step_u = static_cast<std::uint32_t>(step);
      if (step_u > health_.max_step_us) health_.max_step_us = step_u;
      if (static_cast<double>(step) > config_.gap_factor * nominal_us) {
        ++health_.gaps;
        const double missing = std::round(static_cast<double>(step) / nominal_us) - 1.0;
        if (missing > 0) health_.missed_frames += static_cast<std::uint64_t>(missing);
      } else {
        // Gaps stay out of the rate: it measures the device's clocking, gaps are counted apart.
        period_us_ = period_us_ == 0.0 ? static_cast<double>(step)
                                       : period_us_ + config_.rate_smoothing *
                                                          (static_cast<double>(step) - period_us_);
        health_.rate_hz = 1e6 / period_us_;
      }
    }
  }
  health_.last_counter_us = frame.counter_us;
  ++health_.frames;
}

}  // namespace posed::drivers::a9
