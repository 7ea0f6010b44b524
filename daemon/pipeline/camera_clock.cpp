#include "daemon/pipeline/camera_clock.hpp"

namespace posed::pipeline {

namespace {
ClockSyncConfig clock_config(const config::CameraSection& s, DeviceClockKind kind) {
  return ClockSyncConfig{
      .kind = kind, .nominal_rate_hz = s.rate_hz, .latency = Duration::from_seconds(s.latency_s)};
}
}  // namespace

// The D4xx stamps count µs in 32 bits whatever the config calls the clock ("hardware_ns" names
// where the time comes from), so the metadata clock always unwraps a 32-bit µs counter.
CameraClock::CameraClock(const config::CameraSection& section)
    : use_metadata_(section.clock_kind != "none"),
      hardware_(clock_config(section, DeviceClockKind::kCounterUs32Bit)),
      clockless_(clock_config(section, DeviceClockKind::kNone)) {}

bool CameraClock::on_metadata(std::span<const std::byte> bytes) {
  drivers::camera::D4xxFrameMetadata md;
  const auto status = drivers::camera::parse_d4xx_metadata(bytes, md);
  if (status != drivers::camera::MetadataStatus::kOk &&
      status != drivers::camera::MetadataStatus::kNoIntelBlocks) {
    ++bad_metadata_;
    pending_.reset();
    return false;
  }
  pending_ = md;
  return true;
}

HostTime CameraClock::stamp(HostTime arrival) {
  std::optional<drivers::camera::D4xxFrameMetadata> md;
  md.swap(pending_);
  if (use_metadata_ && md && (md->has_capture_timing || md->has_pts)) {
    // sensor_timestamp is the exposure midpoint; the UVC PTS (start of exposure on the same
    // clock) only when the capture-timing block is missing.
    const std::uint32_t us = md->has_capture_timing ? md->sensor_timestamp_us : md->pts_us;
    const HostTime t = hardware_.map_raw(us, arrival);
    last_event_ = hardware_.last_event();
    seen_metadata_ = true;
    ++hardware_stamped_;
    return t;
  }
  if (seen_metadata_) {
    // A frame whose metadata went missing: the clock's estimate of arrival - latency is the
    // best stamp; the stamper's separate fit would disagree by its own offset.
    last_event_ = ClockEvent::kNone;
    return arrival - hardware_.config().latency;
  }
  const ClocklessStamper::Stamp s = clockless_.stamp(arrival);
  last_event_ = clockless_.last_event();
  return s.stamp;
}

ClockSyncStatus CameraClock::status() const {
  return seen_metadata_ ? hardware_.status() : clockless_.status();
}

}  // namespace posed::pipeline
