#pragma once
// StreamPairer<V, Th>: pairs frames of two camera streams running at different rates (the
// D435i's visible frames at 15 Hz, the PLUG 617's thermal frames at 25 Hz) by nearest stamp,
// within a tolerance. Generic over the payloads (Image, or anything MeasurementSpan stamps;
// a frame's stamp is its span end).
//
// The rule:
//   * Visible frames are decided one at a time, in stamp order. A visible frame v is paired
//     with the pending thermal frame whose stamp is nearest to v's (a tie goes to the earlier
//     one), provided |thermal - visible| <= tolerance; otherwise v is released alone.
//   * The choice is made only once it can no longer change: when a thermal frame stamped at or
//     after v has been pushed (thermal frames come in stamp order, so every later one is
//     farther), or when the caller's watermark (see pop()) reaches v + tolerance (no thermal
//     frame still to come could be within tolerance).
//   * Each thermal frame is used at most once, and pairs never cross: once a thermal frame is
//     chosen, the older pending thermal frames can no longer be chosen by any later visible
//     frame and are released alone. A thermal frame is also released alone as soon as no
//     visible frame, present or future, can be within tolerance of it.
//   * Every frame pushed is released exactly once: in a pair, or alone (counted:
//     unpaired_visible, unpaired_thermal). Releases come out in stamp order within each stream;
//     a pair's place in the output is its visible stamp.
//
// Each stream must be pushed in stamp order; a frame not newer than the previous one of its
// stream is dropped and counted (never reordered, DESIGN.md Time). Pending frames are bounded
// per stream; on overflow the oldest pending frame of that stream is dropped and counted. A
// stalled stream only holds the other back until the watermark passes, so callers that can
// lose a camera should pass one.
//
// Pure: no clock is read; the watermark is the caller's. No allocation after construction.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "core/sync/measurement_span.hpp"
#include "core/time.hpp"

namespace posed {

struct StreamPairerConfig {
  /// largest |thermal stamp - visible stamp| of a pair; ClockSyncConfig::pairing_tolerance [ns]
  Duration tolerance = Duration::from_ms(10);
  /// frames of each stream that may wait for a decision at once [1]
  std::size_t pending_capacity = 8;
};

struct StreamPairerCounters {
  /// visible / thermal frames accepted by push [1]
  std::uint64_t visible_pushed = 0;
  std::uint64_t thermal_pushed = 0;
  /// pairs released [1]
  std::uint64_t paired = 0;
  /// visible frames released without a thermal partner [1]
  std::uint64_t unpaired_visible = 0;
  /// thermal frames released without a visible partner [1]
  std::uint64_t unpaired_thermal = 0;
  /// frames not newer than the previous frame of their stream, dropped [1]
  std::uint64_t visible_out_of_order = 0;
  std::uint64_t thermal_out_of_order = 0;
  /// pending frames dropped because their stream's queue was full [1]
  std::uint64_t visible_overflow_dropped = 0;
  std::uint64_t thermal_overflow_dropped = 0;
};

/// What push_visible()/push_thermal() did with a frame.
enum class PairerPushResult : std::uint8_t {
  kQueued,               ///< waiting for a decision
  kQueuedDroppedOldest,  ///< queued; the oldest pending frame of the stream was dropped
  kDroppedOutOfOrder     ///< not newer than the previous frame of the stream: dropped
};

/// One release: a pair, or a frame alone (exactly one of the two is empty then).
template <class V, class Th>
struct FramePair {
  std::optional<V> visible;
  std::optional<Th> thermal;
  /// thermal stamp minus visible stamp when paired, else 0 [ns]
  Duration thermal_minus_visible;

  bool paired() const { return visible.has_value() && thermal.has_value(); }
};

template <class V, class Th, class SpanOf = MeasurementSpan>
class StreamPairer {
 public:
  explicit StreamPairer(const StreamPairerConfig& config, SpanOf span_of = SpanOf{})
      : config_(config), span_of_(std::move(span_of)) {
    visible_.reserve(config.pending_capacity);
    thermal_.reserve(config.pending_capacity);
  }

  PairerPushResult push_visible(V&& frame) {
    return push(std::move(frame), visible_, last_visible_, counters_.visible_pushed,
                counters_.visible_out_of_order, counters_.visible_overflow_dropped);
  }

  PairerPushResult push_thermal(Th&& frame) {
    return push(std::move(frame), thermal_, last_thermal_, counters_.thermal_pushed,
                counters_.thermal_out_of_order, counters_.thermal_overflow_dropped);
  }

  /// The next decided release, or nullopt when nothing can be decided yet. Call in a loop.
  /// `watermark`: the caller's promise that every frame of either stream stamped at or before
  /// it has been pushed (e.g. the host time now minus the larger stream latency). Pass
  /// std::nullopt to decide only from the frames themselves.
  std::optional<FramePair<V, Th>> pop(std::optional<HostTime> watermark = std::nullopt) {
    const Duration tol = config_.tolerance;
    if (!thermal_.empty() && thermal_orphaned(thermal_.front().stamp, watermark)) {
      return release_thermal_alone();
    }
    if (visible_.empty()) return std::nullopt;
    const HostTime v = visible_.front().stamp;
    const bool decided =
        (last_thermal_ && *last_thermal_ >= v) || (watermark && *watermark >= v + tol);
    if (!decided) return std::nullopt;
    std::optional<std::size_t> best;
    Duration best_distance;
    for (std::size_t i = 0; i < thermal_.size(); ++i) {
      const Duration d = distance(thermal_[i].stamp, v);
      if (d <= tol && (!best || d < best_distance)) {  // strict: a tie keeps the earlier one
        best = i;
        best_distance = d;
      }
    }
    if (!best) {
      ++counters_.unpaired_visible;
      FramePair<V, Th> out{std::move(visible_.front().frame), std::nullopt, Duration{}};
      visible_.erase(visible_.begin());
      return out;
    }
    // Pairs never cross: thermal frames older than the chosen one go out alone first (they are
    // older than v, so stamp order is kept); the same choice is found again on the next call.
    if (*best > 0) return release_thermal_alone();
    ++counters_.paired;
    FramePair<V, Th> out{std::move(visible_.front().frame), std::move(thermal_.front().frame),
                         thermal_.front().stamp - v};
    visible_.erase(visible_.begin());
    thermal_.erase(thermal_.begin());
    return out;
  }

  /// frames waiting for a decision [1]
  std::size_t pending_visible() const { return visible_.size(); }
  std::size_t pending_thermal() const { return thermal_.size(); }

  const StreamPairerCounters& counters() const { return counters_; }
  const StreamPairerConfig& config() const { return config_; }

 private:
  template <class F>
  struct Pending {
    HostTime stamp;
    F frame;
  };

  static Duration distance(HostTime a, HostTime b) { return a < b ? b - a : a - b; }

  template <class F>
  PairerPushResult push(F&& frame, std::vector<Pending<F>>& queue, std::optional<HostTime>& last,
                        std::uint64_t& pushed, std::uint64_t& out_of_order,
                        std::uint64_t& overflow) {
    const HostTime stamp = span_of_(frame).end;
    if (last && stamp <= *last) {
      ++out_of_order;
      return PairerPushResult::kDroppedOutOfOrder;
    }
    ++pushed;
    last = stamp;
    PairerPushResult result = PairerPushResult::kQueued;
    if (queue.size() >= config_.pending_capacity) {
      ++overflow;
      if (queue.empty()) return PairerPushResult::kQueuedDroppedOldest;  // capacity 0
      queue.erase(queue.begin());
      result = PairerPushResult::kQueuedDroppedOldest;
    }
    queue.push_back(Pending<F>{stamp, std::move(frame)});
    return result;
  }

  /// True when no visible frame, pending or still to come, can be within tolerance of a
  /// thermal frame stamped `t` (visible frames come in stamp order).
  bool thermal_orphaned(HostTime t, std::optional<HostTime> watermark) const {
    const HostTime last_chance = t + config_.tolerance;
    if (!visible_.empty()) return visible_.front().stamp > last_chance;
    // Every future visible frame is newer than the last one pushed and than the watermark.
    return (last_visible_ && *last_visible_ >= last_chance) ||
           (watermark && *watermark >= last_chance);
  }

  std::optional<FramePair<V, Th>> release_thermal_alone() {
    ++counters_.unpaired_thermal;
    FramePair<V, Th> out{std::nullopt, std::move(thermal_.front().frame), Duration{}};
    thermal_.erase(thermal_.begin());
    return out;
  }

  StreamPairerConfig config_;
  SpanOf span_of_;
  /// pending frames of each stream in stamp order; capacity reserved once
  std::vector<Pending<V>> visible_;
  std::vector<Pending<Th>> thermal_;
  /// stamp of the newest frame pushed per stream (possibly already released) [ns]
  std::optional<HostTime> last_visible_;
  std::optional<HostTime> last_thermal_;
  StreamPairerCounters counters_;
};

}  // namespace posed
