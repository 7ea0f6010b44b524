#include "daemon/pipeline/latency_histogram.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace posed::pipeline {

int LatencyHistogram::bucket_of(std::int64_t ns) {
  if (ns < kSub) return static_cast<int>(std::max<std::int64_t>(ns, 0));
  const auto v = static_cast<std::uint64_t>(ns);
  const int power = static_cast<int>(std::bit_width(v)) - 1;  // >= kSubBits
  const int shift = power - kSubBits;
  const int sub = static_cast<int>(v >> shift) - kSub;  // 0 .. kSub-1
  return std::min(kSub + shift * kSub + sub, kBuckets - 1);
}

std::int64_t LatencyHistogram::upper_edge(int bucket) {
  if (bucket < kSub) return bucket;
  const int shift = (bucket - kSub) / kSub;
  const int sub = (bucket - kSub) % kSub;
  return ((static_cast<std::int64_t>(kSub + sub + 1)) << shift) - 1;
}

void LatencyHistogram::record(Duration latency) {
  const std::int64_t ns = std::max<std::int64_t>(latency.ns, 0);
  buckets_[static_cast<std::size_t>(bucket_of(ns))].fetch_add(1, std::memory_order_relaxed);
  if (ns > max_ns_.load(std::memory_order_relaxed)) max_ns_.store(ns, std::memory_order_relaxed);
  count_.fetch_add(1, std::memory_order_relaxed);
}

std::int64_t LatencyHistogram::percentile_ns(double p) const {
  std::uint64_t total = 0;
  for (const auto& b : buckets_) total += b.load(std::memory_order_relaxed);
  if (total == 0) return 0;
  // Nearest rank: the smallest value with at least p of the values at or below it.
  const auto rank = std::max<std::uint64_t>(
      1,
      static_cast<std::uint64_t>(std::ceil(std::clamp(p, 0.0, 1.0) * static_cast<double>(total))));
  std::uint64_t seen = 0;
  for (int i = 0; i < kBuckets; ++i) {
    seen += buckets_[static_cast<std::size_t>(i)].load(std::memory_order_relaxed);
    if (seen >= rank) return std::min(upper_edge(i), max_ns());
  }
  return max_ns();
}

LatencySummary LatencyHistogram::summary() const {
  LatencySummary s;
  s.count = count();
  s.p50_ms = static_cast<double>(percentile_ns(0.50)) * 1e-6;
  s.p99_ms = static_cast<double>(percentile_ns(0.99)) * 1e-6;
  s.max_ms = static_cast<double>(max_ns()) * 1e-6;
  return s;
}

}  // namespace posed::pipeline
