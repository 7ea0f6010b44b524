#pragma once
// The decoder side of D4xxVideoSource's delivery convention: a frame's metadata buffer arrives
// on channel 1 immediately before the frame on channel 0 (live or replayed from a recording).
// The latch parses the metadata when it arrives and hands it to the frame that follows. Pure,
// never throws; a malformed metadata buffer or a frame without one is counted, not an error.

#include <cstdint>
#include <span>

#include "drivers/camera/d4xx_metadata.hpp"

namespace posed::drivers::camera {

struct D4xxMetadataLatchCounters {
  std::uint64_t metadata_ok = 0;      ///< metadata buffers parsed
  std::uint64_t metadata_bad = 0;     ///< metadata buffers that failed to parse (dropped)
  std::uint64_t metadata_unused = 0;  ///< metadata replaced by the next before any frame came
  std::uint64_t frames_with = 0;      ///< frames that got metadata
  std::uint64_t frames_without = 0;   ///< frames that came without
};

class D4xxMetadataLatch {
 public:
  /// A channel-1 chunk. Holds the parsed metadata for the next frame unless it is malformed.
  MetadataStatus on_metadata(std::span<const std::byte> bytes);
  /// A channel-0 chunk arrived: the metadata of this frame, or nullptr. Valid until the next
  /// on_metadata(); the latch is empty afterwards.
  const D4xxFrameMetadata* on_frame();
  const D4xxMetadataLatchCounters& counters() const { return counters_; }

 private:
  D4xxFrameMetadata held_;
  D4xxFrameMetadata handed_;
  bool have_ = false;
  D4xxMetadataLatchCounters counters_;
};

}  // namespace posed::drivers::camera
