#include "daemon/pipeline/stage_support.hpp"

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"

namespace posed::pipeline {

void Heartbeat::beat() { ns_.store(drivers::host_now().ns, std::memory_order_relaxed); }

void StreamCounters::publish_clock(const ClockSyncStatus& clock) {
  std::lock_guard lock(clock_mutex_);
  clock_ = clock;
}

ClockSyncStatus StreamCounters::clock() const {
  std::lock_guard lock(clock_mutex_);
  return clock_;
}

void fill_stream_status(StreamStatus& out, const StreamCounters& counters,
                        const drivers::Source& source, HostTime now, StreamHealthMemory& memory,
                        std::optional<MergedStreamHealth> merged) {
  out.received = counters.received.load(std::memory_order_relaxed);
  out.refused = source.counters().rejected;
  out.decoded = counters.decoded.load(std::memory_order_relaxed);
  out.undecodable = counters.undecodable.load(std::memory_order_relaxed);
  out.malformed = counters.malformed.load(std::memory_order_relaxed) + out.undecodable;
  out.dropped = counters.dropped.load(std::memory_order_relaxed);
  const ClockSyncStatus clock = counters.clock();
  out.clock_offset_ns = clock.offset.ns;
  out.clock_drift_ppm = clock.drift_ppm;
  out.clock_jitter_ns = static_cast<double>(clock.jitter.ns);
  out.clock_uncertainty_ns = static_cast<double>(clock.uncertainty.ns);
  const Duration silent = now - (merged ? merged->newest_stamp : clock.last_arrival);
  const bool stale = clock.samples == 0 || silent > kStreamStaleAfter;
  out.clock_state =
      std::string(to_string(stale && clock.samples > 0 ? SyncState::kLost : clock.state));
  const std::uint64_t bad = out.malformed + out.dropped;
  if (bad > memory.bad) memory.bad_rose = now;
  memory.bad = bad;
  const bool recently_bad =
      merged ? merged->degraded : memory.bad_rose && now - *memory.bad_rose <= kStreamDegradedFor;
  if (counters.device_lost.load(std::memory_order_relaxed)) {
    out.health = "device_lost";
  } else if (out.decoded == 0 || stale) {
    out.health = "no_data";
  } else if (recently_bad) {
    out.health = "degraded";
  } else {
    out.health = "ok";
  }
  // Not the first data (no_data -> ok at start-up is no news), but every change after it. A
  // replay's changes are logged by the fusion stage, exactly in the data's time (a report
  // sampled on the wall clock can miss one: a replay catches up on a silence at once).
  if (out.health != memory.last_health && memory.had_data && !merged) {
    // The journal's record of a stream failing and coming back, in the data's time.
    char why[96] = "";
    if (out.health == "no_data" && clock.samples > 0) {
      std::snprintf(why, sizeof why, " (silent for %.2f s)", silent.seconds());
    } else if (out.health == "degraded") {
      std::snprintf(why, sizeof why, " (%llu malformed, %llu dropped so far)",
                    static_cast<unsigned long long>(out.malformed),
                    static_cast<unsigned long long>(out.dropped));
    }
    const log::Level level = out.health == "ok" ? log::Level::kNotice : log::Level::kWarning;
    log::write(level, "stream %s: %s -> %s at %.3f s%s", out.name.c_str(),
               memory.last_health.c_str(), out.health.c_str(), now.seconds(), why);
  }
  memory.last_health = out.health;
  memory.had_data = memory.had_data || out.health == "ok" || out.health == "degraded";
}

bool SourceReader::next(drivers::RawChunk& chunk) {
  for (;;) {
    heartbeat_.beat();
    const drivers::ReadStatus rs = source_.read(chunk, kStageReadTimeout);
    if (rs == drivers::ReadStatus::kEndOfStream) return false;
    if (rs == drivers::ReadStatus::kDeviceLost) {
      if (!reported_lost_) {
        POSED_LOG_WARN("%.*s: device lost; waiting for it to come back",
                       static_cast<int>(stream_.size()), stream_.data());
      }
      reported_lost_ = true;
      counters_.device_lost.store(true);
      continue;
    }
    if (rs != drivers::ReadStatus::kData) continue;
    if (reported_lost_) {
      POSED_LOG_NOTICE("%.*s: device back", static_cast<int>(stream_.size()), stream_.data());
    }
    reported_lost_ = false;
    counters_.device_lost.store(false);
    counters_.received.fetch_add(1, std::memory_order_relaxed);
    return true;
  }
}

void SourceReader::undecodable(const drivers::RawChunk& chunk) {
  // Counted, and said once: e.g. a recording of a stream this build cannot decode.
  counters_.undecodable.fetch_add(1, std::memory_order_relaxed);
  if (reported_format_) return;
  reported_format_ = true;
  const std::string_view format = wire_format(chunk);
  POSED_LOG_ERROR("%.*s: no decoder for wire format '%.*s' (channel %u): chunks skipped",
                  static_cast<int>(stream_.size()), stream_.data(), static_cast<int>(format.size()),
                  format.data(), chunk.channel);
}

// The schema admits only these names (config_schema.cpp), so the last branch is "none".
DeviceClockKind clock_kind_from(const std::string& name) {
  if (name == "counter_us_32bit") return DeviceClockKind::kCounterUs32Bit;
  if (name == "us_past_hour") return DeviceClockKind::kUsPastHour;
  if (name == "hardware_ns") return DeviceClockKind::kHardwareNs;
  return DeviceClockKind::kNone;
}

DropPolicy queue_policy(const drivers::Source* source) {
  return source && !source->live() ? DropPolicy::kBlockWithTimeout : DropPolicy::kDropOldest;
}

void log_clock_event(std::string_view stream, ClockEvent event) {
  // Outliers are counted (the clock's status), not logged: a corrupt burst has hundreds.
  if (event == ClockEvent::kNone || event == ClockEvent::kOutlier) return;
  const bool bad =
      event == ClockEvent::kReset || event == ClockEvent::kJump || event == ClockEvent::kLost;
  log::write(bad ? log::Level::kWarning : log::Level::kInfo, "%.*s clock: %.*s",
             static_cast<int>(stream.size()), stream.data(),
             static_cast<int>(to_string(event).size()), to_string(event).data());
}

}  // namespace posed::pipeline
