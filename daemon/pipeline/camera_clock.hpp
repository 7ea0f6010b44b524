#pragma once
// Puts a camera's frames on the host clock (DESIGN.md, Time). Two ways, chosen per frame:
//  - The D435i sends per-frame metadata (drivers/camera/d4xx_metadata.hpp) just before each
//    frame (source channel 1). Its sensor timestamp (exposure midpoint, the device's 1 MHz clock,
//    32 bits) goes through ClockSync, which unwraps it and fits offset and drift against the
//    arrivals: stamps free of USB jitter, drift-corrected.
//  - Without metadata (the PLUG 617 has no clock; a D435i without metadata enabled; a recording
//    of frames only), a ClocklessStamper regularises arrival - latency to the frame period.
// Once metadata was seen, a frame without it is stamped from the clock's current estimate so a
// lost metadata buffer does not jump the stamps between the two models.

#include <cstdint>
#include <optional>
#include <span>

#include "core/sync/clock_sync.hpp"
#include "core/sync/clockless_stamper.hpp"
#include "core/time.hpp"
#include "daemon/config/posed_config.hpp"
#include "drivers/camera/d4xx_metadata.hpp"

namespace posed::pipeline {

class CameraClock {
 public:
  /// `section`: the camera's config (rate, latency, clock kind).
  explicit CameraClock(const config::CameraSection& section);

  /// The metadata buffer that precedes the next frame. False (and counted) when unparsable.
  bool on_metadata(std::span<const std::byte> bytes);
  /// The exposure midpoint of the frame that arrived at `arrival`, on the host clock.
  HostTime stamp(HostTime arrival);

  ClockEvent last_event() const { return last_event_; }
  /// The figures of the model in use (metadata clock when seen, else the clockless stamper).
  ClockSyncStatus status() const;
  /// metadata buffers that could not be parsed [1]
  std::uint64_t bad_metadata() const { return bad_metadata_; }
  /// frames stamped from the hardware clock [1]
  std::uint64_t hardware_stamped() const { return hardware_stamped_; }

 private:
  bool use_metadata_;
  ClockSync hardware_;
  ClocklessStamper clockless_;
  std::optional<drivers::camera::D4xxFrameMetadata> pending_;
  bool seen_metadata_ = false;
  ClockEvent last_event_ = ClockEvent::kNone;
  std::uint64_t bad_metadata_ = 0;
  std::uint64_t hardware_stamped_ = 0;
};

}  // namespace posed::pipeline
