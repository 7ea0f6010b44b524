#pragma once
// ImuBuffer: the recent IMU samples on the host clock, in stamp order, in a ring whose capacity
// is fixed at construction (no allocation afterwards). It is the clock that releases every other
// measurement (DESIGN.md, Time: a measurement is processed only once the IMU covers it), and the
// source of the IMU bundles handed out with them (deskew of a lidar scan, preintegration between
// two frames).
//
// Out-of-order and duplicate samples: the only policy is kDrop (count and discard). Why not
// reorder: once a newer sample is in, bundles up to that stamp may already have been released
// and integrated; slotting an older sample in afterwards would make the result depend on when
// the consumer happened to run (replays would stop being repeatable), and a sample that arrives
// behind a newer one after ClockSync has a stamp error larger than the IMU period, so it is
// suspect anyway. The policy is still a named enum so the config and the status report can
// name it, and so a second policy has an obvious place to go.
//
// Pure: no clock is read; events travel as return values and counters.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "core/measurements.hpp"
#include "core/sync/stamped_ring.hpp"
#include "core/time.hpp"

namespace posed {

/// What ImuBuffer does with a sample not newer than the newest it holds.
enum class ImuOrderPolicy : std::uint8_t {
  kDrop  ///< count and discard (never reorder: see imu_buffer.hpp)
};

/// What push() did with one sample.
enum class ImuPushResult : std::uint8_t {
  kAccepted,           ///< stored as the newest
  kAcceptedOverwrote,  ///< stored; the ring was full and its oldest sample was overwritten
  kDroppedDuplicate,   ///< same stamp as the newest: discarded, counted
  kDroppedOutOfOrder,  ///< older than the newest: discarded, counted
  kDroppedNoCapacity   ///< the buffer was built with capacity 0
};

constexpr std::string_view to_string(ImuOrderPolicy p) {
  switch (p) {
    case ImuOrderPolicy::kDrop:
      return "drop";
  }
  return "unknown";
}

constexpr std::string_view to_string(ImuPushResult r) {
  switch (r) {
    case ImuPushResult::kAccepted:
      return "accepted";
    case ImuPushResult::kAcceptedOverwrote:
      return "accepted_overwrote";
    case ImuPushResult::kDroppedDuplicate:
      return "dropped_duplicate";
    case ImuPushResult::kDroppedOutOfOrder:
      return "dropped_out_of_order";
    case ImuPushResult::kDroppedNoCapacity:
      return "dropped_no_capacity";
  }
  return "unknown";
}

struct ImuBufferConfig {
  /// samples held; e.g. 2 s at 200 Hz = 400 covers a 10 Hz scan with a wide margin [1]
  std::size_t capacity = 400;
  /// what to do with out-of-order and duplicate samples
  ImuOrderPolicy order_policy = ImuOrderPolicy::kDrop;
};

struct ImuBufferCounters {
  /// samples stored [1]
  std::uint64_t accepted = 0;
  /// samples older than the newest held, discarded under kDrop [1]
  std::uint64_t out_of_order_dropped = 0;
  /// samples with the same stamp as the newest held, discarded under kDrop [1]
  std::uint64_t duplicate_dropped = 0;
  /// samples lost because the ring was full when a newer one came (capacity too small for how
  /// far behind the consumer runs) [1]
  std::uint64_t overwritten = 0;
  /// samples removed by discard_before() [1]
  std::uint64_t discarded = 0;
};

/// What samples_between() wrote. The samples are in strictly increasing stamp order.
struct ImuRange {
  /// samples written [1]
  std::size_t count = 0;
  /// the first sample written is the newest one older than t0 (the lower bracket)
  bool has_before = false;
  /// the last sample written is the oldest one newer than t1 (the upper bracket)
  bool has_after = false;
  /// the samples reach back to t0: the first stamp is <= t0, so the rate at t0 can be
  /// interpolated rather than extrapolated
  bool covers_begin = false;
  /// the samples reach forward to t1: the last stamp is >= t1
  bool covers_end = false;
};

class ImuBuffer {
 public:
  explicit ImuBuffer(const ImuBufferConfig& config);

  /// Stores `sample` if it is newer than every sample held; otherwise applies the order policy.
  ImuPushResult push(const ImuSample& sample);

  /// True when the newest sample held is stamped at or after `t` (IMU time >= t).
  bool covers(HostTime t) const;

  /// Writes into `out` (cleared first), in stamp order:
  ///   1. the newest sample with stamp < t0, if one is held (lower bracket);
  ///   2. every held sample with t0 <= stamp <= t1;
  ///   3. the oldest sample with stamp > t1, if one is held (upper bracket).
  /// The brackets are included even when a sample sits exactly on t0 or t1, so the rule has no
  /// special cases; the caller interpolates at t0 and t1 from the first two / last two samples.
  /// With t0 > t1 nothing is written. `out` allocates only when its capacity is too small:
  /// reserve it once (capacity() is always enough).
  ImuRange samples_between(HostTime t0, HostTime t1, std::vector<ImuSample>& out) const;

  /// The sample at `t`, linear in angular rate and specific force (and device stamp) between
  /// the two held samples that bracket it; exact when a sample sits on t. nullopt when t is
  /// outside [oldest, newest] stamp: the buffer does not extrapolate.
  std::optional<ImuSample> interpolate(HostTime t) const;

  /// Removes samples older than `t`, except the newest of them, which stays as the lower
  /// bracket so that interpolate(t) and samples_between(t, ..) still work. Returns how many
  /// were removed.
  std::size_t discard_before(HostTime t);

  std::size_t size() const { return ring_.size(); }
  bool empty() const { return ring_.empty(); }
  std::size_t capacity() const { return ring_.capacity(); }
  /// stamp of the oldest / newest sample held; only meaningful when !empty()
  HostTime oldest_stamp() const { return ring_.front().stamp; }
  HostTime newest_stamp() const { return ring_.back().stamp; }
  /// the i-th oldest sample held; i < size()
  const ImuSample& operator[](std::size_t i) const { return ring_[i]; }

  const ImuBufferCounters& counters() const { return counters_; }
  const ImuBufferConfig& config() const { return config_; }

 private:
  ImuBufferConfig config_;
  StampedRing<ImuSample> ring_;
  ImuBufferCounters counters_;
};

}  // namespace posed
