#include "tools/hil/lateness_histogram.hpp"

#include <algorithm>
#include <cmath>

namespace posed::hil {

void LatenessHistogram::add(Duration lateness) {
  const std::int64_t ns = std::max<std::int64_t>(0, lateness.ns);
  const auto bucket = std::min<std::size_t>(kBuckets, static_cast<std::size_t>(ns / kBucketNs));
  ++buckets_[bucket];
  ++count_;
  max_ns_ = std::max(max_ns_, ns);
}

Duration LatenessHistogram::quantile(double q) const {
  if (count_ == 0) return Duration::from_ns(0);
  q = std::clamp(q, 0.0, 1.0);
  // The rank of the q-quantile among count_ sorted values (1-based, nearest-rank definition).
  const auto rank = std::max<std::uint64_t>(
      1, static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_))));
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < kBuckets; ++b) {
    seen += buckets_[b];
    if (seen >= rank) {
      return Duration::from_ns(std::min(max_ns_, static_cast<std::int64_t>(b + 1) * kBucketNs));
    }
  }
  return Duration::from_ns(max_ns_);
}

void LatenessHistogram::merge(const LatenessHistogram& other) {
  for (std::size_t b = 0; b <= kBuckets; ++b) buckets_[b] += other.buckets_[b];
  count_ += other.count_;
  max_ns_ = std::max(max_ns_, other.max_ns_);
}

}  // namespace posed::hil
