// The latency histogram against exact percentiles of known delays.

#include "daemon/pipeline/latency_histogram.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace posed::pipeline {
namespace {

std::int64_t exact_percentile(std::vector<std::int64_t> v, double p) {
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size())));
  return v[std::max<std::size_t>(rank, 1) - 1];
}

TEST(LatencyHistogram, EmptyReportsZero) {
  const LatencyHistogram h;
  EXPECT_EQ(h.count(), 0u);
  EXPECT_EQ(h.percentile_ns(0.5), 0);
  EXPECT_EQ(h.summary().max_ms, 0.0);
}

TEST(LatencyHistogram, UniformDelaysGiveTheirPercentilesWithinABucket) {
  LatencyHistogram h;
  for (int us = 1; us <= 1000; ++us) h.record(Duration::from_us(us));
  EXPECT_EQ(h.count(), 1000u);
  EXPECT_EQ(h.max_ns(), 1'000'000);  // exact
  // Reported values are a bucket's upper edge: at or above the truth, within 1/16.
  EXPECT_GE(h.percentile_ns(0.5), 500'000);
  EXPECT_LE(h.percentile_ns(0.5), 500'000 * 17 / 16);
  EXPECT_GE(h.percentile_ns(0.99), 990'000);
  EXPECT_LE(h.percentile_ns(0.99), 1'000'000);  // capped at the maximum
  const LatencySummary s = h.summary();
  EXPECT_NEAR(s.p50_ms, 0.5, 0.5 / 16);
  EXPECT_DOUBLE_EQ(s.max_ms, 1.0);
}

TEST(LatencyHistogram, ASkewedDelayDistributionMatchesItsExactPercentiles) {
  // Transport-like delays: 200 us floor, exponential tail, a few 20 ms stalls.
  std::mt19937_64 rng(7);
  std::exponential_distribution<double> tail(1.0 / 300e3);
  std::vector<std::int64_t> delays;
  LatencyHistogram h;
  for (int i = 0; i < 20000; ++i) {
    std::int64_t ns = 200'000 + static_cast<std::int64_t>(tail(rng));
    if (i % 1000 == 999) ns = 20'000'000 + i;
    delays.push_back(ns);
    h.record(Duration::from_ns(ns));
  }
  for (const double p : {0.5, 0.9, 0.99, 0.999}) {
    const auto exact = exact_percentile(delays, p);
    EXPECT_GE(h.percentile_ns(p), exact) << p;
    EXPECT_LE(h.percentile_ns(p), exact + exact / 16 + 1) << p;
  }
  EXPECT_EQ(h.max_ns(), *std::max_element(delays.begin(), delays.end()));
}

TEST(LatencyHistogram, NegativeLatenciesCountAsZero) {
  LatencyHistogram h;
  h.record(Duration::from_ns(-5000));
  h.record(Duration::from_ns(3));
  EXPECT_EQ(h.count(), 2u);
  EXPECT_EQ(h.percentile_ns(0.5), 0);
  EXPECT_EQ(h.max_ns(), 3);
}

TEST(LatencyHistogram, HoursFitWithoutOverflow) {
  LatencyHistogram h;
  h.record(Duration::from_s(3600 * 30));
  EXPECT_EQ(h.max_ns(), std::int64_t{3600} * 30 * 1'000'000'000);
  EXPECT_GT(h.percentile_ns(1.0), 0);
}

}  // namespace
}  // namespace posed::pipeline
