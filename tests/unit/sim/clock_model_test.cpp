// The clock model gives what it was configured with: offset, drift, one-sided delay with the
// configured minimum and mean, FIFO arrivals.

#include "tools/sim/clock_model.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <vector>

namespace posed::sim {
namespace {

TEST(ClockModel, OffsetDriftAndInverse) {
  ClockModel c({5'000'000'000, 37.0, 0, 0}, 0, 1);
  EXPECT_EQ(c.device_at(Duration::from_ns(0)).ns, 5'000'000'000);
  // After 100 s the device has gained 37 ppm · 100 s = 3.7 ms.
  EXPECT_EQ(c.device_at(Duration::from_s(100)).ns, 5'000'000'000 + 100'000'000'000 + 3'700'000);
  for (std::int64_t t : {0ll, 1ll, 999'999'999ll, 3'600'000'000'123ll}) {
    const Duration back = c.true_at(c.device_at(Duration::from_ns(t)));
    EXPECT_LE(std::abs(back.ns - t), 1) << t;
  }
}

TEST(ClockModel, ArrivalIsOneSidedExponentialAndFifo) {
  const std::int64_t latency = 400'000, mean = 250'000, epoch = 7'000'000'000;
  ClockModel c({0, 0, latency, mean}, epoch, 42);
  double sum = 0;
  std::int64_t min_delay = INT64_MAX, last = INT64_MIN;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Duration sent = Duration::from_ms(10) * i;  // far apart: FIFO never binds
    const HostTime a = c.arrival(sent);
    const std::int64_t delay = a.ns - epoch - sent.ns;
    ASSERT_GE(delay, latency);
    ASSERT_GT(a.ns, last);
    last = a.ns;
    min_delay = std::min(min_delay, delay);
    sum += static_cast<double>(delay - latency);
  }
  EXPECT_NEAR(sum / n, static_cast<double>(mean), 0.05 * mean);
  EXPECT_LT(min_delay - latency, 1000);  // the minimum is reached: ClockSync's premise
  // Sent closer together than the jitter: arrivals still never reorder.
  ClockModel d({0, 0, latency, 5'000'000}, 0, 3);
  std::int64_t prev = INT64_MIN;
  for (int i = 0; i < 1000; ++i) {
    const HostTime a = d.arrival(Duration::from_us(100) * i);
    ASSERT_GT(a.ns, prev);
    prev = a.ns;
  }
}

TEST(ClockModel, DriftRecoveredByFit) {
  // Fitting device time against arrival time recovers the drift within a few ppm.
  ClockModel c({123'456'789, -42.0, 1'000'000, 200'000}, 1'000'000'000, 9);
  Eigen::MatrixXd A(2000, 2);
  Eigen::VectorXd y(2000);
  for (int i = 0; i < 2000; ++i) {
    const Duration t = Duration::from_ms(50) * i;
    A(i, 0) = static_cast<double>(c.arrival(t).ns) * 1e-9;
    A(i, 1) = 1.0;
    y(i) = static_cast<double>(c.device_at(t).ns) * 1e-9;
  }
  const Eigen::Vector2d fit = A.colPivHouseholderQr().solve(y);
  EXPECT_NEAR((fit(0) - 1.0) * 1e6, -42.0, 3.0);
}

}  // namespace
}  // namespace posed::sim
