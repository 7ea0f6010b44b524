#pragma once
// ClockSync: puts one stream's device stamps on the host monotonic clock, online.
//
// Model: a sample stamped d by the device arrives at host time
//     h = offset + d * (1 + drift) + latency + delay,   delay >= 0,
// where latency is the stream's fixed minimum transport latency (configured: it cannot be seen
// from timing) and delay is one-sided: USB/driver/scheduler jitter, with rare long spikes.
//
// Estimator: a minimum-delay filter feeding a lower-envelope (convex hull) fit; see
// lower_envelope.hpp. Why this and not a least-squares or Kalman fit of h against d: the delay
// is not zero-mean or Gaussian (it is one-sided, skewed, with 50 ms spikes), so any averaging
// estimator is biased by the mean delay and dragged by spikes, while the least-delayed samples
// sit within microseconds of the true line (the error of a minimum falls as 1/n, an average's
// only as 1/sqrt(n)). The per-bin minimum keeps memory bounded (one point per bin,
// `window_bins` bins) and throws the spikes away for free; the lower convex hull of the bin
// minima gives the envelope height at the centroid of each half of the window (the
// Moon/Skelly/Towsley linear programme), and the line through the two heights gives offset and
// drift without a noise model or tuning. The fit is redone when a bin opens or a sample lands
// below the line, so the cost per sample is O(1) amortised.
//
// Streams that share one device clock (D435i colour frames and IMU) should share one ClockSync:
// feed it the high-rate stream and stamp the others with to_host(), which is more accurate
// than fitting a 15 Hz stream on its own.
//
// Discontinuities: a sample below the envelope by more than `jump_threshold` (impossible for a
// delay) is a forward jump, one above it by more than `max_transport_delay` a reset (device time
// went backwards) - once `discontinuity_confirm_samples` consecutive such samples agree with each
// other on the new line. Until then each is an outlier: stamped from its arrival, counted,
// reported as kOutlier, and not learnt from, so a corrupt stamp (bit flips in an unchecksummed
// packet) costs one sample instead of the whole estimate. `jump_confirm_samples` consecutive
// samples above the envelope by more than the threshold are a backward step. Each discontinuity
// clears the envelope and re-converges (the drift estimate is kept, the crystal did not change),
// is counted, and is reported once through last_event().
//
// Pure: no clock is read; the caller passes each sample's host arrival time.

#include <cstdint>

#include "core/sync/clock_sync_types.hpp"
#include "core/sync/counter_unwrapper.hpp"
#include "core/sync/lower_envelope.hpp"
#include "core/time.hpp"

namespace posed {

class ClockSync {
 public:
  explicit ClockSync(const ClockSyncConfig& config);

  /// Observes one sample (unwrapped device stamp, host arrival time) and returns its stamp on
  /// the host clock. Samples must be passed in arrival order; device stamps may be out of order.
  HostTime map(DeviceTime device_stamp, HostTime host_arrival);

  /// Like map(), from the raw stamp as the device sends it: a counter value for
  /// kCounterUs32Bit, µs past the hour for kUsPastHour, ns for kHardwareNs. Unwraps it first
  /// (guided by host time). For kNone or an out-of-range raw value the sample is rejected
  /// (counted) and arrival - latency is returned.
  HostTime map_raw(std::uint64_t raw_stamp, HostTime host_arrival);

  /// The host-clock stamp of a device stamp under the current estimate, without observing.
  /// Before any sample: device stamp - latency, unchanged.
  HostTime to_host(DeviceTime device_stamp) const;

  /// The event raised by the most recent map()/map_raw() call (kNone almost always).
  ClockEvent last_event() const { return last_event_; }

  ClockSyncStatus status() const;
  /// status(), reporting kLost when no sample arrived within `lost_after` before `now`.
  ClockSyncStatus status(HostTime now) const;

  const ClockSyncConfig& config() const { return config_; }

 private:
  void restart(std::int64_t x, std::int64_t y);
  void refit();
  void raise(ClockEvent e);

  ClockSyncConfig config_;
  LowerEnvelope envelope_;
  CounterUnwrapper unwrapper_;
  ClockSyncStatus status_;
  ClockEvent last_event_ = ClockEvent::kNone;
  bool have_sample_ = false;
  bool have_raw_ = false;
  HostTime last_raw_arrival_;
  /// newest device stamp seen since the last restart [ns]
  std::int64_t newest_device_ns_ = 0;
  /// the line before the last restart, and when that was: late samples from before a
  /// discontinuity still arrive for up to max_transport_delay and must not look like another
  bool have_previous_line_ = false;
  LowerEnvelope::Line previous_line_;
  HostTime restarted_at_;
  /// consecutive samples far above the envelope [1]
  std::uint32_t high_run_ = 0;
  /// consecutive outliers that agree on one line (a discontinuity being confirmed) [1]
  std::uint32_t outlier_run_ = 0;
  /// host minus device time of the first of them [ns]
  std::int64_t outlier_offset_ns_ = 0;
  /// device stamp of the newest of them [ns]
  std::int64_t outlier_device_ns_ = 0;
  /// drift kept across restarts: the device's crystal does not change when it resets [1]
  double drift_ = 0.0;
  /// mean delay above the envelope, exponentially weighted [ns]
  double jitter_ns_ = 0.0;
};

}  // namespace posed
