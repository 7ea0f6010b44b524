// LatenessHistogram: nearest-rank quantiles to the bucket's upper edge, the exact maximum, the
// overflow bucket, early sends, and merging.

#include "tools/hil/lateness_histogram.hpp"

#include <gtest/gtest.h>

namespace posed::hil {
namespace lateness_histogram_test {

TEST(LatenessHistogram, EmptyReportsZero) {
  LatenessHistogram h;
  EXPECT_EQ(h.count(), 0u);
  EXPECT_EQ(h.quantile(0.5).ns, 0);
  EXPECT_EQ(h.max().ns, 0);
}

TEST(LatenessHistogram, QuantilesAreNearestRankToTheBucketEdge) {
  LatenessHistogram h;
  // 1..100 ms in 1 ms steps: the p50 is 50 ms, the p99 99 ms, each rounded up to its 10 µs edge.
  for (int i = 1; i <= 100; ++i) h.add(Duration::from_us(i * 1000 - 3));
  EXPECT_EQ(h.count(), 100u);
  EXPECT_EQ(h.quantile(0.5).ns, 50'000'000);
  EXPECT_EQ(h.quantile(0.99).ns, 99'000'000);
  // The top sample's bucket edge (100 ms) is above the largest sample: capped at the exact max.
  EXPECT_EQ(h.quantile(1.0).ns, 99'997'000);
  EXPECT_EQ(h.max().ns, 99'997'000);
  EXPECT_EQ(h.overflow(), 0u);
}

TEST(LatenessHistogram, NeverUnderstatesAndNeverExceedsTheMax) {
  LatenessHistogram h;
  h.add(Duration::from_ns(12'345));
  // One sample: every quantile is that sample's bucket edge, capped by the exact maximum.
  EXPECT_EQ(h.quantile(0.5).ns, 12'345);
  h.add(Duration::from_ns(15'000));
  EXPECT_EQ(h.quantile(0.5).ns, 15'000);  // bucket [10, 20) µs, capped at the max 15 µs
  EXPECT_GE(h.quantile(0.5).ns, 12'345);
}

TEST(LatenessHistogram, LateBeyond100MsGoesToOverflowWithTheExactMax) {
  LatenessHistogram h;
  h.add(Duration::from_ms(1));
  h.add(Duration::from_ms(250));
  EXPECT_EQ(h.overflow(), 1u);
  EXPECT_EQ(h.max().ns, 250'000'000);
  EXPECT_EQ(h.quantile(1.0).ns, 250'000'000);
  EXPECT_EQ(h.quantile(0.5).ns, 1'010'000);  // 1 ms lies in the bucket [1.00, 1.01) ms
}

TEST(LatenessHistogram, EarlySendsCountAsOnTime) {
  LatenessHistogram h;
  h.add(Duration::from_ms(-3));
  EXPECT_EQ(h.count(), 1u);
  EXPECT_EQ(h.max().ns, 0);
  EXPECT_EQ(h.quantile(0.99).ns, 0);
}

TEST(LatenessHistogram, MergeAddsCountsAndKeepsTheLargerMax) {
  LatenessHistogram a, b;
  a.add(Duration::from_ms(2));
  b.add(Duration::from_ms(7));
  b.add(Duration::from_ms(8));
  a.merge(b);
  EXPECT_EQ(a.count(), 3u);
  EXPECT_EQ(a.max().ns, 8'000'000);
  EXPECT_EQ(a.quantile(0.5).ns, 7'010'000);
}

}  // namespace lateness_histogram_test
}  // namespace posed::hil
