#include "drivers/camera/d4xx_metadata_latch.hpp"

namespace posed::drivers::camera {

MetadataStatus D4xxMetadataLatch::on_metadata(std::span<const std::byte> bytes) {
  if (have_) ++counters_.metadata_unused;
  have_ = false;
  const MetadataStatus s = parse_d4xx_metadata(bytes, held_);
  // A UVC header without Intel blocks still carries the host SOF time and the PTS: keep it.
  if (s == MetadataStatus::kOk || s == MetadataStatus::kNoIntelBlocks) {
    ++counters_.metadata_ok;
    have_ = true;
  } else {
    ++counters_.metadata_bad;
  }
  return s;
}

const D4xxFrameMetadata* D4xxMetadataLatch::on_frame() {
  if (!have_) {
    ++counters_.frames_without;
    return nullptr;
  }
  have_ = false;
  ++counters_.frames_with;
  handed_ = held_;
  return &handed_;
}

}  // namespace posed::drivers::camera
