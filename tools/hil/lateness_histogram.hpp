#pragma once
// How late each message of a paced replay went out, against its due time on the absolute
// schedule. Fixed-size buckets (10 µs wide up to 100 ms, then one overflow bucket) so an
// hours-long replay costs 40 kB, not a sample per packet; the maximum is kept exactly.

#include <array>
#include <cstdint>

#include "core/time.hpp"

namespace posed::hil {

class LatenessHistogram {
 public:
  /// bucket width [ns]
  static constexpr std::int64_t kBucketNs = 10'000;
  /// buckets below the overflow one: 10 µs x 10000 = 100 ms
  static constexpr std::size_t kBuckets = 10'000;

  /// Adds one message's lateness (send time minus due time); early sends count as 0.
  void add(Duration lateness);
  std::uint64_t count() const { return count_; }
  /// largest lateness seen [ns] (0 when empty)
  Duration max() const { return Duration::from_ns(max_ns_); }
  /// The q-quantile (0 <= q <= 1) to the bucket's upper edge, so it never understates; the
  /// exact max when it falls in the overflow bucket. 0 when empty.
  Duration quantile(double q) const;
  /// messages later than 100 ms (the overflow bucket)
  std::uint64_t overflow() const { return buckets_[kBuckets]; }
  void merge(const LatenessHistogram& other);

 private:
  std::array<std::uint64_t, kBuckets + 1> buckets_{};
  std::uint64_t count_ = 0;
  std::int64_t max_ns_ = 0;
};

}  // namespace posed::hil
