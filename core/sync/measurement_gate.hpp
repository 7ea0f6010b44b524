#pragma once
// MeasurementGate<T>: holds measurements of one stream (lidar scans, images, visible/thermal
// pairs: anything MeasurementSpan gives a host-time span) until the IMU covers them, then
// releases them in stamp order, each with its IMU bundle (DESIGN.md, Time: a measurement is
// processed only once the IMU covers it, IMU time >= measurement time).
//
// Release rule: the oldest pending measurement (by span end; for a lidar scan its end stamp)
// is released as soon as ImuBuffer::covers(end) holds; pop_ready() is called after every IMU
// push and every measurement push, so "as soon as" means at the first call that sees it.
//
// The bundle: the IMU samples for [begin, end] where end is the measurement's end and begin is
// the earlier of its own begin (a scan's first firing) and the end of the measurement this gate
// released before it. So one bundle serves both the deskew of a scan and the preintegration from
// the previous measurement (the packaging between two consecutive stamps of seed 002), with no
// gap between consecutive bundles even when a measurement was dropped upstream. Samples are
// taken by ImuBuffer::samples_between(begin, end), brackets included; see its contract.
//
// Late measurements (end older than the last released end; the stream arrived out of order by
// more than one release) follow a named LatePolicy and are counted, never silently reordered:
//   kDrop     discard (late_dropped);
//   kRelease  release at the next pop, ahead of the covered ones (it is older than all of them),
//             with ReleaseKind::kLate and the IMU for its own span only (whatever is still held),
//             counted (late_released). The last released stamp does not move backwards.
// A measurement that is not late but older than one still pending is slotted into stamp order
// (it was never released, so nothing downstream saw the other order) and counted
// (out_of_order).
//
// Bounded: at most `pending_capacity` measurements wait; on overflow the oldest (which may be
// the new one) is dropped and counted (overflow_dropped). No allocation after construction.
// Payloads may be move-only (LidarScan and Image hold a PayloadPool::Lease): a dropped
// measurement is destroyed at once, returning its buffer to the pool.
//
// IMU memory is the caller's: several gates (lidar, camera) read one ImuBuffer, so the caller
// discards IMU older than the minimum of every gate's oldest_needed().
//
// Pure: no clock is read; events travel as return values and counters.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "core/measurements.hpp"
#include "core/sync/imu_buffer.hpp"
#include "core/sync/measurement_span.hpp"
#include "core/time.hpp"

namespace posed {

/// Scans the lidar-inertial estimator's gate holds at most. The lidar stage's scan buffers must
/// outnumber these plus its queue: while the gate holds scans waiting for the IMU, the fusion
/// stage's stamp-ordered merge waits for the lidar's next scan, which needs a free buffer; with
/// every buffer held the lidar stopped for good (a burst of corrupt packets cut many tiny
/// scans: docs/faults.md).
inline constexpr std::size_t kLidarScanGateCapacity = 8;

/// What a gate does with a measurement older than the last one it released.
enum class LatePolicy : std::uint8_t {
  kDrop,    ///< discard it, counted (late_dropped)
  kRelease  ///< release it at the next pop with whatever IMU is held, flagged kLate, counted
};

/// What push() did with one measurement.
enum class GatePushResult : std::uint8_t {
  kQueued,               ///< waiting for the IMU to cover it
  kQueuedDroppedOldest,  ///< queued; the gate was full, its oldest pending measurement dropped
  kDroppedOverflow,      ///< the gate was full and this was the oldest: dropped
  kLateDropped,          ///< late under LatePolicy::kDrop: dropped
  kLateQueued            ///< late under LatePolicy::kRelease: released at the next pop
};

/// Why a bundle was released.
enum class ReleaseKind : std::uint8_t {
  kCovered,  ///< the IMU covers the measurement (the normal case)
  kLate,     ///< a late measurement under LatePolicy::kRelease; its IMU may be incomplete
  kDrained   ///< pop_drain() at end of stream, before the IMU covered it; IMU incomplete
};

constexpr std::string_view to_string(LatePolicy p) {
  switch (p) {
    case LatePolicy::kDrop:
      return "drop";
    case LatePolicy::kRelease:
      return "release";
  }
  return "unknown";
}

constexpr std::string_view to_string(ReleaseKind k) {
  switch (k) {
    case ReleaseKind::kCovered:
      return "covered";
    case ReleaseKind::kLate:
      return "late";
    case ReleaseKind::kDrained:
      return "drained";
  }
  return "unknown";
}

struct MeasurementGateConfig {
  /// measurements that may wait for the IMU at once; a 10 Hz stream waiting up to 0.5 s for a
  /// stalled IMU needs 5 [1]
  std::size_t pending_capacity = 8;
  /// what to do with a measurement older than the last released
  LatePolicy late_policy = LatePolicy::kDrop;
};

struct MeasurementGateCounters {
  /// measurements offered to push() [1]
  std::uint64_t pushed = 0;
  /// bundles released, any kind [1]
  std::uint64_t released = 0;
  /// late measurements discarded under kDrop [1]
  std::uint64_t late_dropped = 0;
  /// late measurements released under kRelease [1]
  std::uint64_t late_released = 0;
  /// measurements dropped because the gate was full [1]
  std::uint64_t overflow_dropped = 0;
  /// measurements that arrived behind a newer pending one and were slotted into order [1]
  std::uint64_t out_of_order = 0;
  /// measurements released by pop_drain() before the IMU covered them [1]
  std::uint64_t drained_uncovered = 0;
};

/// One released measurement and its IMU.
template <class T>
struct Bundle {
  T measurement;
  /// the interval the IMU samples were taken for (see measurement_gate.hpp) [ns]
  TimeSpan imu_span;
  /// what ImuBuffer::samples_between() wrote into the caller's vector for imu_span
  ImuRange imu;
  ReleaseKind kind = ReleaseKind::kCovered;
};

template <class T, class SpanOf = MeasurementSpan>
class MeasurementGate {
 public:
  explicit MeasurementGate(const MeasurementGateConfig& config, SpanOf span_of = SpanOf{})
      : config_(config), span_of_(std::move(span_of)) {
    pending_.reserve(config.pending_capacity);
  }

  GatePushResult push(T&& measurement) {
    ++counters_.pushed;
    const TimeSpan span = span_of_(measurement);
    const bool late = have_released_ && span.end < last_released_end_;
    if (late && config_.late_policy == LatePolicy::kDrop) {
      ++counters_.late_dropped;
      return GatePushResult::kLateDropped;
    }
    // After the last entry with the same or an older end: equal ends keep arrival order.
    auto pos = std::upper_bound(pending_.begin(), pending_.end(), span.end,
                                [](HostTime t, const Entry& e) { return t < e.span.end; });
    GatePushResult result = late ? GatePushResult::kLateQueued : GatePushResult::kQueued;
    if (pending_.size() >= config_.pending_capacity) {
      ++counters_.overflow_dropped;
      if (pos == pending_.begin()) return GatePushResult::kDroppedOverflow;
      pending_.erase(pending_.begin());
      --pos;
      if (!late) result = GatePushResult::kQueuedDroppedOldest;
    }
    if (pos != pending_.end()) ++counters_.out_of_order;
    pending_.insert(pos, Entry{span, late, std::move(measurement)});
    return result;
  }

  /// The oldest pending measurement once the IMU covers it (or at once if it is late under
  /// kRelease), with its IMU samples written into `imu_out` (cleared first; reserve it once to
  /// ImuBuffer::capacity() to avoid allocation). nullopt when nothing is ready. Call in a loop.
  std::optional<Bundle<T>> pop_ready(const ImuBuffer& imu, std::vector<ImuSample>& imu_out) {
    if (pending_.empty()) return std::nullopt;
    const Entry& front = pending_.front();
    if (!front.late && !imu.covers(front.span.end)) return std::nullopt;
    return release_front(imu, imu_out);
  }

  /// End of stream: releases the oldest pending measurement whether or not the IMU covers it
  /// (ReleaseKind::kDrained when it does not; counted). nullopt when nothing is pending.
  std::optional<Bundle<T>> pop_drain(const ImuBuffer& imu, std::vector<ImuSample>& imu_out) {
    if (pending_.empty()) return std::nullopt;
    return release_front(imu, imu_out);
  }

  /// The earliest stamp a future pop may ask the IMU for; nullopt when none is known yet (no
  /// release and nothing pending). The caller may discard IMU samples before the minimum of
  /// this over every gate sharing the ImuBuffer.
  std::optional<HostTime> oldest_needed() const {
    std::optional<HostTime> t;
    if (have_released_) t = last_released_end_;
    for (const Entry& e : pending_) {
      if (!t || e.span.begin < *t) t = e.span.begin;
    }
    return t;
  }

  /// span end of the newest measurement released in order; only meaningful if has_released()
  HostTime last_released() const { return last_released_end_; }
  bool has_released() const { return have_released_; }
  /// measurements waiting [1]
  std::size_t pending() const { return pending_.size(); }

  const MeasurementGateCounters& counters() const { return counters_; }
  const MeasurementGateConfig& config() const { return config_; }

 private:
  struct Entry {
    TimeSpan span;
    bool late = false;
    T value;
  };

  std::optional<Bundle<T>> release_front(const ImuBuffer& imu, std::vector<ImuSample>& imu_out) {
    Entry& front = pending_.front();
    TimeSpan imu_span = front.span;
    ReleaseKind kind = ReleaseKind::kCovered;
    if (front.late) {
      kind = ReleaseKind::kLate;
      ++counters_.late_released;
    } else {
      if (have_released_ && last_released_end_ < imu_span.begin) {
        imu_span.begin = last_released_end_;
      }
      if (!imu.covers(imu_span.end)) {
        kind = ReleaseKind::kDrained;
        ++counters_.drained_uncovered;
      }
      have_released_ = true;
      last_released_end_ = front.span.end;
    }
    const ImuRange range = imu.samples_between(imu_span.begin, imu_span.end, imu_out);
    std::optional<Bundle<T>> out{Bundle<T>{std::move(front.value), imu_span, range, kind}};
    pending_.erase(pending_.begin());
    ++counters_.released;
    return out;
  }

  MeasurementGateConfig config_;
  SpanOf span_of_;
  /// waiting measurements, sorted by span end (ties in arrival order); capacity reserved once
  std::vector<Entry> pending_;
  MeasurementGateCounters counters_;
  bool have_released_ = false;
  /// span end of the newest measurement released in order [ns]
  HostTime last_released_end_;
};

}  // namespace posed
