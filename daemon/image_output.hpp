#pragma once
// rt/posed/image/compressed off the estimate's threads: the camera front end's tracked image with
// its features drawn on it (vision::feature_overlay), JPEG, at most publish.image_rate_hz and only
// while someone reads it (a DDS reader, Foxglove, a recording). The front end's thread (its own,
// or the fusion thread) copies the image and the frame's features into a one-slot mailbox; this
// object's thread draws, encodes and writes, so a slow reader or the encoder never delays the
// estimate. A frame not yet written when a newer one comes is replaced (counted).

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <opencv2/core.hpp>
#include <thread>

#include "core/fusion/camera_front_end.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/dds/messages.hpp"

namespace posed {

namespace dds {
class Publisher;
}

struct ImageOutputCounters {
  std::uint64_t images = 0;      ///< rt/posed/image/compressed messages written [count]
  std::uint64_t replaced = 0;    ///< copied but replaced by a newer frame before the write
  std::uint64_t failed = 0;      ///< encodes or writes that failed [count]
  std::uint64_t last_bytes = 0;  ///< JPEG size of the last image [B]
  double encode_ms_total = 0;    ///< drawing and encoding, summed [ms]
};

class ImageOutput final : public fusion::FrontendObserver {
 public:
  /// Starts the writer thread. `publisher` must outlive this object.
  ImageOutput(const config::PosedConfig& config, dds::Publisher& publisher, HostToWall to_wall);
  ~ImageOutput() override;
  ImageOutput(const ImageOutput&) = delete;
  ImageOutput& operator=(const ImageOutput&) = delete;

  /// On the front end's thread, for every frame the configured front end processed.
  void on_frame(const vision::FrontendFrame& frame,
                const vision::VisualFrontend& frontend) override;
  /// Writes what is still waiting and ends the thread. Idempotent.
  void stop();
  ImageOutputCounters counters() const;

 private:
  void run();

  const config::PosedConfig& config_;
  dds::Publisher& publisher_;
  HostToWall to_wall_;
  HostTime next_stamp_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  cv::Mat pending_grey_;
  vision::FrontendFrame pending_frame_;
  bool full_ = false;
  bool stopping_ = false;
  ImageOutputCounters counters_;
  std::thread thread_;
};

}  // namespace posed
