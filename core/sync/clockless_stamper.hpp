#pragma once
// ClocklessStamper: stamps for a stream whose device has no clock (the PLUG 617 over UVC), from
// host arrival times alone.
//
// The naive stamp, arrival - latency, carries the whole USB/driver jitter. But the camera
// exposes frames at a steady period, so frame k's true time is phase + k * period: a line in k.
// We give each frame an index k (from a frame sequence number when the driver has one, such as
// V4L2's buffer sequence, else from the arrival time against the predicted period), treat
// k * nominal_period as a synthetic device clock, and let ClockSync fit the lower envelope of
// the arrivals against it. The stamps then come from the fitted line, so jitter never reaches
// them, the fitted drift is the camera's true period error, and a gap of m periods between
// consecutive indices is m - 1 dropped frames.
//
// Without sequence numbers a frame delayed by most of a period cannot be told from a dropped
// frame: it gets the next index (counted as a drop) and a stamp one period late. The next frame
// then arrives early against its prediction, which corrects the index (index_corrections, and
// the false drop is uncounted) so one late frame never shifts the stamps after it. A frame that
// arrives before its slot is exactly such an ambiguous case, so it enters the fit only once the
// next frame confirms its index.

#include <cstdint>

#include "core/sync/clock_sync.hpp"
#include "core/sync/clock_sync_types.hpp"
#include "core/time.hpp"

namespace posed {

class ClocklessStamper {
 public:
  struct Stamp {
    /// regularised exposure time on the host clock
    HostTime stamp;
    /// frames inferred missing between the previous frame and this one [1]
    std::uint32_t dropped_before = 0;
    /// the frame index used (synthetic device clock = index * nominal period) [1]
    std::int64_t frame_index = 0;
  };

  /// Uses config.nominal_rate_hz (required, > 0) and config.latency. With no usable rate every
  /// stamp is arrival - latency, and each is counted as rejected in the status.
  explicit ClocklessStamper(const ClockSyncConfig& config);

  /// Stamps a frame from its arrival time alone.
  Stamp stamp(HostTime arrival);
  /// Stamps a frame with the driver's frame sequence number (consecutive frames differ by 1;
  /// a larger step is a drop, a step back a stream restart).
  Stamp stamp(HostTime arrival, std::uint64_t sequence);

  /// The event raised by the most recent stamp() call.
  ClockEvent last_event() const { return sync_.last_event(); }
  /// Offset/drift/jitter of the fit (drift = period error), plus dropped_frames.
  ClockSyncStatus status() const;
  ClockSyncStatus status(HostTime now) const;
  /// frame indices corrected after a late frame was mistaken for a drop [1]
  std::uint64_t index_corrections() const { return index_corrections_; }
  /// frames that arrived before their slot and waited for the next frame before entering the
  /// fit (timing-only mode) [1]
  std::uint64_t held_frames() const { return held_frames_; }
  /// the nominal frame period [ns]; 0 when the configuration has no usable rate
  Duration nominal_period() const { return period_; }

 private:
  Stamp observe(HostTime arrival, std::int64_t index, std::uint32_t dropped);

  ClockSyncConfig config_;
  Duration period_;
  ClockSync sync_;
  bool have_frame_ = false;
  std::int64_t last_index_ = 0;
  std::uint64_t last_sequence_ = 0;
  std::uint64_t dropped_frames_ = 0;
  std::uint64_t index_corrections_ = 0;
  std::uint64_t rejected_ = 0;
  std::uint64_t held_frames_ = 0;
  /// a frame that arrived before its slot, waiting for the next frame to confirm its index
  bool pending_ = false;
  std::int64_t pending_index_ = 0;
  HostTime pending_arrival_;
};

}  // namespace posed
