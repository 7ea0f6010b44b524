#pragma once
// Plain structs shared by ClockSync, ClocklessStamper and the daemon: the per-stream clock
// configuration (filled from YAML by the daemon) and the status it publishes over DDS.
// Nothing here reads a clock or logs: events travel as return values and counters.

#include <cstdint>
#include <string_view>

#include "core/time.hpp"

namespace posed {

/// What kind of clock a device stamps its samples with.
enum class DeviceClockKind : std::uint8_t {
  kCounterUs32Bit,  ///< free-running 32-bit microsecond counter (Handsfree A9); wraps every ~71.6
                    ///< min
  kUsPastHour,      ///< microseconds past the hour (VLP-32C); rolls over every hour
  kHardwareNs,      ///< a monotonic hardware clock already in ns (D435i frame metadata)
  kNone             ///< no device clock (PLUG 617 over UVC): host arrival time only
};

/// Where a stream's clock estimate stands.
enum class SyncState : std::uint8_t {
  kConverging,  ///< too little data since start or since the last reset/jump
  kLocked,      ///< offset and drift estimated; stamps are trustworthy
  kLost         ///< samples disagree with the estimate, or none arrived for too long
};

/// Something the caller should log once. Returned by the call that caused it, never repeated.
enum class ClockEvent : std::uint8_t {
  kNone,
  kLocked,        ///< the estimate (re)converged
  kLost,          ///< samples stopped agreeing with the estimate (possible jump being confirmed)
  kCounterWrap,   ///< an N-bit device counter wrapped (expected, informational)
  kHourRollover,  ///< µs-past-the-hour rolled over (expected, informational)
  kReset,         ///< device time went backwards: device reset or restart; re-converging
  kJump,          ///< device time jumped against host time; re-converging
  kOutlier,       ///< a stamp off the line by more than a delay can explain, not (yet) confirmed
                  ///< by the samples after it: a corrupt stamp, or the first of a discontinuity
};

constexpr std::string_view to_string(DeviceClockKind k) {
  switch (k) {
    case DeviceClockKind::kCounterUs32Bit:
      return "counter_us_32bit";
    case DeviceClockKind::kUsPastHour:
      return "us_past_hour";
    case DeviceClockKind::kHardwareNs:
      return "hardware_ns";
    case DeviceClockKind::kNone:
      return "none";
  }
  return "unknown";
}

constexpr std::string_view to_string(SyncState s) {
  switch (s) {
    case SyncState::kConverging:
      return "converging";
    case SyncState::kLocked:
      return "locked";
    case SyncState::kLost:
      return "lost";
  }
  return "unknown";
}

constexpr std::string_view to_string(ClockEvent e) {
  switch (e) {
    case ClockEvent::kNone:
      return "none";
    case ClockEvent::kLocked:
      return "locked";
    case ClockEvent::kLost:
      return "lost";
    case ClockEvent::kCounterWrap:
      return "counter_wrap";
    case ClockEvent::kHourRollover:
      return "hour_rollover";
    case ClockEvent::kReset:
      return "reset";
    case ClockEvent::kJump:
      return "jump";
    case ClockEvent::kOutlier:
      return "outlier";
  }
  return "unknown";
}

/// Per-stream clock configuration. Defaults suit every sensor of the M2DGR rig; the daemon only
/// needs to set `kind`, `nominal_rate_hz` and `latency` per stream.
struct ClockSyncConfig {
  /// how the device stamps its samples
  DeviceClockKind kind = DeviceClockKind::kHardwareNs;
  /// nominal sample/frame rate [Hz]; required for kNone (frame period), informational otherwise
  double nominal_rate_hz = 0.0;
  /// minimum transport latency from the device's stamp (or exposure) to host arrival [ns];
  /// subtracted from the lower envelope because it cannot be observed from timing alone
  Duration latency = Duration::from_ns(0);
  /// largest stamp difference for pairing this stream with another (visible/thermal) [ns]
  Duration pairing_tolerance = Duration::from_ms(10);
  /// span of device time per envelope bin; each bin keeps its minimum-delay sample [ns]
  Duration bin_width = Duration::from_ms(200);
  /// number of bins kept (bounded memory); window = bin_width * window_bins, 25.6 s by default:
  /// long enough that a 15 Hz stream pins the drift, short against crystal drift changes [1]
  std::uint32_t window_bins = 128;
  /// filled bins needed before the estimate is called locked [1]
  std::uint32_t lock_bins = 5;
  /// a sample below the envelope by more than this is a forward jump of device time (a delay
  /// can never be negative); one above it by more than this is suspect [ns]
  Duration jump_threshold = Duration::from_ms(20);
  /// consecutive suspect samples that confirm a backward step of device time or a lasting
  /// change of latency (a single late sample is just a transport spike) [1]
  std::uint32_t jump_confirm_samples = 10;
  /// consecutive samples, each off the line beyond any delay and agreeing with each other, that
  /// confirm a reset or a forward jump; fewer are outliers (a corrupt stamp: an unchecksummed
  /// lidar packet with flipped bits), stamped from their arrival and not learnt from [1]
  std::uint32_t discontinuity_confirm_samples = 3;
  /// a sample above the envelope by more than this cannot be a transport delay: a reset (device
  /// time went backwards) or jump, declared at once without waiting for confirmation [ns]
  Duration max_transport_delay = Duration::from_ms(500);
  /// drift is estimated once the bin minima span this much device time; before that the
  /// previous estimate (0 at start) is used: short baselines give wild slopes [ns]
  Duration drift_min_span = Duration::from_s(2);
  /// drift beyond this is not believed (a crystal that far off is broken); fits are clamped [ppm]
  double max_drift_ppm = 1000.0;
  /// no sample for this long (host time) reports the stream as lost [ns]
  Duration lost_after = Duration::from_s(1);
};

/// Per-stream clock status for logs and the DDS status topic.
struct ClockSyncStatus {
  SyncState state = SyncState::kConverging;
  /// host time minus device time at the newest sample, latency included [ns]
  Duration offset = Duration::from_ns(0);
  /// device clock rate error against the host clock: host = device * (1 + drift) [ppm]
  double drift_ppm = 0.0;
  /// mean transport delay of samples above the lower envelope (one-sided jitter) [ns]
  Duration jitter = Duration::from_ns(0);
  /// expected size of stamp errors: the envelope rests on the least-delayed of n samples, so its
  /// error scales as (mean height of the per-bin minima above it) / n; reported as 4x that,
  /// which the simulations put at about the 90th percentile of the error. A scale, not a bound [ns]
  Duration uncertainty = Duration::from_ns(0);
  /// device stamp of the newest sample, unwrapped [ns]
  DeviceTime last_device_stamp;
  /// host arrival time of the newest sample [ns]
  HostTime last_arrival;
  /// samples observed [1]
  std::uint64_t samples = 0;
  /// device resets detected (device time went backwards) [1]
  std::uint64_t resets = 0;
  /// device time jumps detected (forward, or a confirmed backward step) [1]
  std::uint64_t jumps = 0;
  /// counter wraps or hour rollovers unwrapped [1]
  std::uint64_t wraps = 0;
  /// samples whose device stamp is older than an earlier one (out-of-order arrival) [1]
  std::uint64_t out_of_order = 0;
  /// samples rejected as bad input (raw stamp out of range, no device clock, too old) [1]
  std::uint64_t rejected = 0;
  /// samples off the line beyond any delay that the samples after them did not confirm as a
  /// discontinuity, plus those that led up to one (ClockEvent::kOutlier) [1]
  std::uint64_t outliers = 0;
  /// transitions into kLocked [1]
  std::uint64_t locks = 0;
  /// frames inferred missing from the period (clockless streams only) [1]
  std::uint64_t dropped_frames = 0;
};

}  // namespace posed
