#pragma once
// Annotated images of the camera front end for a person to look at (`posectl inspect frontend
// --save-frames DIR`): per saved frame a 2x2 mosaic of the enhanced visible image, the thermal
// image registered into the visible camera, their DWT fusion, and the tracked image with its
// features (colour by track length, a ring around those with lidar depth, labelled in metres).

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "core/fusion/camera_front_end.hpp"

namespace posed::posectl {

struct SnapshotOptions {
  std::string directory;             ///< where the PNGs go; empty = none
  std::uint64_t every_frames = 30;   ///< one snapshot per this many frames of the mode [1]
  std::uint64_t max_snapshots = 12;  ///< per mode [1]
};

class FrontendSnapshots final : public fusion::FrontendObserver {
 public:
  explicit FrontendSnapshots(SnapshotOptions options);
  void on_frame(const vision::FrontendFrame& frame,
                const vision::VisualFrontend& frontend) override;
  /// frames seen, all modes [1]; read from other threads for progress
  std::uint64_t frames() const { return frames_.load(std::memory_order_relaxed); }
  const std::vector<std::string>& written() const { return written_; }
  const std::string& error() const { return error_; }

 private:
  SnapshotOptions options_;
  std::atomic<std::uint64_t> frames_{0};
  std::uint64_t seen_[3] = {0, 0, 0};
  std::uint64_t saved_[3] = {0, 0, 0};
  std::vector<std::string> written_;
  std::string error_;
};

}  // namespace posed::posectl
