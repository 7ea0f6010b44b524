#include "core/sync/clockless_stamper.hpp"

#include <algorithm>
#include <cmath>

namespace posed {
namespace {

Duration period_of(double rate_hz) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz) || rate_hz > 1e6) return Duration::from_ns(0);
  return Duration::from_ns(std::llround(1e9 / rate_hz));
}

ClockSyncConfig synthetic_clock_config(ClockSyncConfig c) {
  // The synthetic device clock is index * period in ns: nothing to unwrap.
  c.kind = DeviceClockKind::kHardwareNs;
  return c;
}

}  // namespace

ClocklessStamper::ClocklessStamper(const ClockSyncConfig& config)
    : config_(config),
      period_(period_of(config.nominal_rate_hz)),
      sync_(synthetic_clock_config(config)) {}

ClocklessStamper::Stamp ClocklessStamper::stamp(HostTime arrival) {
  if (period_.ns <= 0) {
    ++rejected_;
    return Stamp{arrival - config_.latency, 0, 0};
  }
  if (!have_frame_) {
    have_frame_ = true;
    return observe(arrival, 0, 0);
  }
  // Where the envelope puts the previous frame's arrival (its stamp + latency); the new frame
  // arrives `step` periods later plus its own one-sided delay. Delays up to 7/8 of a period are
  // read as delay, early arrivals up to 1/8 of a period as estimation error.
  const HostTime previous_envelope =
      sync_.to_host(DeviceTime::from_ns(last_index_ * period_.ns)) + config_.latency;
  const double period_ns =
      static_cast<double>(period_.ns) * (1.0 + sync_.status().drift_ppm * 1e-6);
  const double periods = static_cast<double>((arrival - previous_envelope).ns) / period_ns;
  const auto step = static_cast<std::int64_t>(std::floor(periods + 0.125));
  std::uint32_t dropped = 0;
  if (step <= 0) {
    // Earlier than any new frame could arrive: the previous frame was late, not preceded by a
    // drop, and got an index too high. This frame's index is right again; undo the false drop,
    // and never let the wrongly indexed frame into the fit.
    ++index_corrections_;
    const auto undo = static_cast<std::uint64_t>(1 - step);
    dropped_frames_ -= std::min(dropped_frames_, undo);
    pending_ = false;
  } else {
    dropped = static_cast<std::uint32_t>(step - 1);
    dropped_frames_ += dropped;
    if (pending_) {
      // The held frame is confirmed: this one came a whole period or more after it.
      sync_.map(DeviceTime::from_ns(pending_index_ * period_.ns), pending_arrival_);
      pending_ = false;
    }
  }
  const std::int64_t index = last_index_ + step;
  last_index_ = index;
  const DeviceTime device = DeviceTime::from_ns(index * period_.ns);
  if (periods - static_cast<double>(step) >= 0.0) {
    // At or after its slot: right, or late (above the envelope) — harmless to the fit either
    // way, so it goes in at once.
    return Stamp{sync_.map(device, arrival), dropped, index};
  }
  // Before its slot. Either the envelope is too high (the frame carries exactly the
  // information that corrects it) or this is a frame of the previous index, so late that it
  // looks early for the next one; feeding that would pull the envelope down by a wrong index.
  // The next frame tells which: hold this one until then.
  pending_ = true;
  pending_index_ = index;
  pending_arrival_ = arrival;
  ++held_frames_;
  return Stamp{sync_.to_host(device), dropped, index};
}

ClocklessStamper::Stamp ClocklessStamper::stamp(HostTime arrival, std::uint64_t sequence) {
  if (period_.ns <= 0) {
    ++rejected_;
    return Stamp{arrival - config_.latency, 0, 0};
  }
  if (!have_frame_) {
    have_frame_ = true;
    last_sequence_ = sequence;
    return observe(arrival, 0, 0);
  }
  // The unsigned difference read as signed: a step back means the stream restarted; the index
  // goes back and ClockSync sees device time going backwards and re-converges (a reset).
  const auto step = static_cast<std::int64_t>(sequence - last_sequence_);
  last_sequence_ = sequence;
  std::uint32_t dropped = 0;
  if (step >= 2) {
    dropped = static_cast<std::uint32_t>(std::min<std::int64_t>(step - 1, 0xFFFF'FFFF));
    dropped_frames_ += dropped;
  }
  return observe(arrival, last_index_ + step, dropped);
}

ClocklessStamper::Stamp ClocklessStamper::observe(HostTime arrival, std::int64_t index,
                                                  std::uint32_t dropped) {
  last_index_ = index;
  return Stamp{sync_.map(DeviceTime::from_ns(index * period_.ns), arrival), dropped, index};
}

ClockSyncStatus ClocklessStamper::status() const {
  ClockSyncStatus s = sync_.status();
  s.dropped_frames = dropped_frames_;
  s.rejected += rejected_;
  return s;
}

ClockSyncStatus ClocklessStamper::status(HostTime now) const {
  ClockSyncStatus s = sync_.status(now);
  s.dropped_frames = dropped_frames_;
  s.rejected += rejected_;
  return s;
}

}  // namespace posed
