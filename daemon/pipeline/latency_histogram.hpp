#pragma once
// Latency figures for every published topic (rt/posed/status, the summary, posectl echo status):
// how long from the host receive time of the newest sample that went into a message to its DDS
// write, and how old the message's stamp is at the write.
//
// Log-linear buckets, as HdrHistogram: values below 16 ns exactly, above in 16 sub-buckets per
// power of two, so a percentile is reported within 1/16 (6 %) above the true value, and the
// maximum exactly. Fixed memory, no allocation, wait-free: one thread records, any thread reads.

#include <array>
#include <atomic>
#include <cstdint>

#include "core/time.hpp"

namespace posed::pipeline {

struct LatencySummary {
  std::uint64_t count = 0;  ///< values recorded [1]
  double p50_ms = 0;        ///< median [ms]
  double p99_ms = 0;        ///< 99th percentile [ms]
  double max_ms = 0;        ///< largest [ms]
};

class LatencyHistogram {
 public:
  /// One latency; negative values (a stamp ahead of the host clock) count as zero.
  void record(Duration latency);
  /// The value at or below which a share `p` (0..1] of the recorded values lie, as the upper
  /// edge of its bucket (capped at the maximum) [ns]; 0 when empty.
  std::int64_t percentile_ns(double p) const;
  std::int64_t max_ns() const { return max_ns_.load(std::memory_order_relaxed); }
  std::uint64_t count() const { return count_.load(std::memory_order_relaxed); }
  LatencySummary summary() const;

 private:
  static constexpr int kSubBits = 4;
  static constexpr int kSub = 1 << kSubBits;  // sub-buckets per power of two
  static constexpr int kPowers = 44;          // up to 2^47 ns (39 h): anything a clock gives
  static constexpr int kBuckets = kSub + kPowers * kSub;
  static int bucket_of(std::int64_t ns);
  static std::int64_t upper_edge(int bucket);

  std::array<std::atomic<std::uint64_t>, kBuckets> buckets_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::int64_t> max_ns_{0};
};

}  // namespace posed::pipeline
