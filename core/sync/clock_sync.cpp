#include "core/sync/clock_sync.hpp"

#include <algorithm>
#include <cmath>

namespace posed {
namespace {

CounterUnwrapper unwrapper_for(DeviceClockKind kind) {
  switch (kind) {
    case DeviceClockKind::kCounterUs32Bit:
      return CounterUnwrapper::with_bits(32, Duration::from_us(1));
    case DeviceClockKind::kUsPastHour:
      return CounterUnwrapper(3'600'000'000ull, Duration::from_us(1));
    case DeviceClockKind::kHardwareNs:
      // A 62-bit ns counter never wraps in practice; unwrapping it is a no-op.
      return CounterUnwrapper::with_bits(62, Duration::from_ns(1));
    case DeviceClockKind::kNone:
      break;
  }
  return CounterUnwrapper(0, Duration::from_ns(1));  // rejects everything
}

/// Weight of a new sample in the jitter average: about the last 64 samples.
constexpr double kJitterWeight = 1.0 / 64.0;

}  // namespace

ClockSync::ClockSync(const ClockSyncConfig& config)
    : config_(config),
      envelope_(config.bin_width, config.window_bins),
      unwrapper_(unwrapper_for(config.kind)) {}

void ClockSync::raise(ClockEvent e) {
  // One event per call: a reset or jump matters more than a wrap in the same sample.
  auto rank = [](ClockEvent ev) {
    switch (ev) {
      case ClockEvent::kNone:
        return 0;
      case ClockEvent::kOutlier:
      case ClockEvent::kCounterWrap:
      case ClockEvent::kHourRollover:
        return 1;
      case ClockEvent::kLocked:
        return 2;
      case ClockEvent::kLost:
        return 3;
      case ClockEvent::kReset:
      case ClockEvent::kJump:
        return 4;
    }
    return 0;
  };
  if (rank(e) >= rank(last_event_)) last_event_ = e;
}

void ClockSync::refit() {
  // Until the minima span drift_min_span the previous drift (0 at start, the device's own after
  // a reset) is a better guess than a slope over a short baseline.
  envelope_.fit(drift_, config_.drift_min_span, std::abs(config_.max_drift_ppm) * 1e-6);
}

void ClockSync::restart(std::int64_t x, std::int64_t y) {
  have_previous_line_ = envelope_.has_fit();
  previous_line_ = envelope_.line();
  restarted_at_ = HostTime::from_ns(x + y);
  envelope_.clear();
  envelope_.add(x, y);
  refit();
  newest_device_ns_ = x;
  high_run_ = 0;
  status_.state = SyncState::kConverging;
}

HostTime ClockSync::map_raw(std::uint64_t raw_stamp, HostTime host_arrival) {
  if (config_.kind == DeviceClockKind::kNone) {
    last_event_ = ClockEvent::kNone;
    ++status_.rejected;
    return host_arrival - config_.latency;
  }
  const Duration elapsed = have_raw_ ? host_arrival - last_raw_arrival_ : Duration::from_ns(0);
  const CounterUnwrapper::Result u = unwrapper_.unwrap(raw_stamp, elapsed);
  if (!u.valid) {
    last_event_ = ClockEvent::kNone;
    ++status_.rejected;
    return host_arrival - config_.latency;
  }
  const CounterUnwrapper unwrapper_before = unwrapper_;
  const HostTime stamp = map(u.stamp, host_arrival);
  if (last_event_ == ClockEvent::kOutlier) {
    // Not learnt from: the next sample unwraps against the last one on the line, so a corrupt
    // stamp cannot move the counter into another period.
    unwrapper_ = unwrapper_before;
    return stamp;
  }
  have_raw_ = true;
  last_raw_arrival_ = host_arrival;
  if (u.wrapped) {
    ++status_.wraps;
    raise(config_.kind == DeviceClockKind::kUsPastHour ? ClockEvent::kHourRollover
                                                       : ClockEvent::kCounterWrap);
  }
  return stamp;
}

HostTime ClockSync::map(DeviceTime device_stamp, HostTime host_arrival) {
  last_event_ = ClockEvent::kNone;
  ++status_.samples;
  const std::int64_t x = device_stamp.ns;
  const std::int64_t y = host_arrival.ns - device_stamp.ns;
  const double threshold = static_cast<double>(config_.jump_threshold.ns);

  if (!have_sample_) {
    have_sample_ = true;
    restart(x, y);
  } else {
    const double r = envelope_.residual(x, y);
    const bool backwards = x < newest_device_ns_;
    if (have_previous_line_ && host_arrival - restarted_at_ <= config_.max_transport_delay &&
        (r < -threshold || r > threshold)) {
      // A straggler from before the last discontinuity: it fits the old line, not the new one.
      const double r_previous = previous_line_.residual(x, y);
      if (r_previous >= -threshold &&
          r_previous <= static_cast<double>(config_.max_transport_delay.ns)) {
        ++status_.out_of_order;
        status_.last_arrival = host_arrival;
        return HostTime::from_ns(x + previous_line_.y_at(x)) - config_.latency;
      }
    }
    // Device time going backwards and a long delay look alike for one sample (a late sample is
    // older than those that overtook it); only a step beyond any plausible delay, or a run of
    // them, is a discontinuity.
    const auto discontinuity = [&] {
      if (backwards) {
        ++status_.resets;
        raise(ClockEvent::kReset);
      } else {
        ++status_.jumps;
        raise(ClockEvent::kJump);
      }
      restart(x, y);
    };
    bool restarted = false;
    if (r < -threshold || r > static_cast<double>(config_.max_transport_delay.ns)) {
      // Below the envelope by more than any estimation error (device time leapt forward), or
      // above it by more than any delay (device time went back): a discontinuity once the
      // samples after it agree on a new line, device time moving on; an outlier until then.
      const bool agrees = outlier_run_ > 0 && x > outlier_device_ns_ &&
                          std::abs(static_cast<double>(y - outlier_offset_ns_)) <= threshold;
      if (!agrees) outlier_offset_ns_ = y;
      outlier_run_ = agrees ? outlier_run_ + 1 : 1;
      outlier_device_ns_ = x;
      if (outlier_run_ < std::max<std::uint32_t>(config_.discontinuity_confirm_samples, 1)) {
        ++status_.outliers;
        raise(ClockEvent::kOutlier);
        status_.last_arrival = host_arrival;
        return host_arrival - config_.latency;
      }
      outlier_run_ = 0;
      if (r < -threshold) {
        ++status_.jumps;
        raise(ClockEvent::kJump);
        restart(x, y);
      } else {
        discontinuity();
      }
      restarted = true;
    } else if (r > threshold) {
      ++high_run_;
      if (high_run_ >= std::max<std::uint32_t>(config_.jump_confirm_samples, 1)) {
        discontinuity();
        restarted = true;
      } else if (high_run_ >= 2 && status_.state == SyncState::kLocked) {
        status_.state = SyncState::kLost;
        raise(ClockEvent::kLost);
      }
    } else {
      high_run_ = 0;
      outlier_run_ = 0;
      if (status_.state == SyncState::kLost) {
        status_.state = SyncState::kLocked;
        raise(ClockEvent::kLocked);
      }
      const double delay = std::max(r, 0.0);
      jitter_ns_ += kJitterWeight * (delay - jitter_ns_);
    }
    if (!restarted) {
      if (backwards) ++status_.out_of_order;
      const LowerEnvelope::AddResult a = envelope_.add(x, y);
      if (a.too_old) ++status_.rejected;
      // Refit when a bin opens (cheap, amortised over the bin's samples), when a sample lands
      // below the line (the line must stay below every point), and while converging.
      if (a.bin_opened || (a.new_minimum && r < 0.0) || status_.state == SyncState::kConverging) {
        refit();
      }
      newest_device_ns_ = std::max(newest_device_ns_, x);
    }
  }
  drift_ = envelope_.slope();

  if (status_.state == SyncState::kConverging &&
      envelope_.filled_bins() >= std::max<std::uint32_t>(config_.lock_bins, 2)) {
    status_.state = SyncState::kLocked;
    ++status_.locks;
    raise(ClockEvent::kLocked);
  }
  status_.last_device_stamp = DeviceTime::from_ns(newest_device_ns_);
  status_.last_arrival = host_arrival;
  return to_host(device_stamp);
}

HostTime ClockSync::to_host(DeviceTime device_stamp) const {
  if (!envelope_.has_fit()) return HostTime::from_ns(device_stamp.ns) - config_.latency;
  return HostTime::from_ns(device_stamp.ns + envelope_.y_at(device_stamp.ns)) - config_.latency;
}

ClockSyncStatus ClockSync::status() const {
  ClockSyncStatus s = status_;
  s.drift_ppm = drift_ * 1e6;
  s.jitter = Duration::from_ns(std::llround(jitter_ns_));
  const std::uint32_t minima = envelope_.filled_bins();
  if (minima > 0) {
    s.uncertainty =
        Duration::from_ns(std::llround(4.0 * envelope_.mean_gap() / static_cast<double>(minima)));
  }
  if (have_sample_)
    s.offset = to_host(s.last_device_stamp) - HostTime::from_ns(s.last_device_stamp.ns);
  return s;
}

ClockSyncStatus ClockSync::status(HostTime now) const {
  ClockSyncStatus s = status();
  if (!have_sample_ || now - status_.last_arrival > config_.lost_after) s.state = SyncState::kLost;
  return s;
}

}  // namespace posed
