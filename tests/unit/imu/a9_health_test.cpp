#include "drivers/imu/a9_health.hpp"

#include <gtest/gtest.h>

namespace posed::drivers::a9 {
namespace {

A9SensorFrame at(std::uint32_t counter_us) {
  A9SensorFrame f;
  f.counter_us = counter_us;
  f.accel_g = {0.f, 0.f, -1.f};
  return f;
}

TEST(A9Health, MeasuresRateFromCounter) {
  A9HealthMonitor m;
  // 200 Hz device although configured for 150: the measured rate must say 200.
  for (std::uint32_t i = 0; i < 400; ++i) m.update(at(i * 5000));
  EXPECT_NEAR(m.health().rate_hz, 200.0, 1e-6);
  EXPECT_EQ(m.health().frames, 400u);
  EXPECT_EQ(m.health().gaps, 0u);
}

TEST(A9Health, CountsGapsDuplicatesBackwardsAndWrap) {
  A9HealthMonitor m;
  const std::uint32_t p = 6667;
  std::uint32_t t = 0xFFFFFFFFu - 3 * p;                 // starts just before the 32-bit wrap
  for (int i = 0; i < 10; ++i, t += p) m.update(at(t));  // crosses the wrap: not a gap
  EXPECT_EQ(m.health().gaps, 0u);
  EXPECT_EQ(m.health().backwards_counters, 0u);
  t += 3 * p;  // two frames lost
  m.update(at(t));
  m.update(at(t));            // duplicate
  m.update(at(t - 100 * p));  // device reset / backwards
  EXPECT_EQ(m.health().gaps, 1u);
  EXPECT_EQ(m.health().missed_frames, 3u);  // step 4p: 3 frames missing
  EXPECT_EQ(m.health().duplicate_counters, 1u);
  EXPECT_EQ(m.health().backwards_counters, 1u);
  EXPECT_EQ(m.health().max_step_us, 4 * p);
  EXPECT_NEAR(m.health().rate_hz, 1e6 / p, 1e-6);
}

TEST(A9Health, CountsSaturation) {
  A9HealthMonitor m;
  A9SensorFrame f = at(0);
  m.update(f);
  f.counter_us = 6667;
  f.gyro_radps[1] = -35.0f;  // beyond ±2000 °/s
  m.update(f);
  f.counter_us = 13334;
  f.gyro_radps[1] = 0.f;
  f.accel_g[0] = 16.0f;
  m.update(f);
  EXPECT_EQ(m.health().saturated, 2u);
}

}  // namespace
}  // namespace posed::drivers::a9
