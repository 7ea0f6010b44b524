#include "daemon/image_output.hpp"

#include <chrono>
#include <opencv2/imgcodecs.hpp>
#include <utility>
#include <vector>

#include "core/vision/feature_overlay.hpp"
#include "core/vision/visual_frontend.hpp"
#include "daemon/dds/publisher.hpp"

namespace posed {

ImageOutput::ImageOutput(const config::PosedConfig& config, dds::Publisher& publisher,
                         HostToWall to_wall)
    : config_(config), publisher_(publisher), to_wall_(to_wall) {
  thread_ = std::thread([this] { run(); });
}

ImageOutput::~ImageOutput() { stop(); }

void ImageOutput::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void ImageOutput::on_frame(const vision::FrontendFrame& frame,
                           const vision::VisualFrontend& frontend) {
  // The rate limit runs on the data's clock, so a max-speed replay thins as live does.
  if (frame.stamp < next_stamp_ || !publisher_.wanted(dds::Topic::kImage)) return;
  const cv::Mat& tracked = frontend.tracked_grey();
  if (tracked.empty() || tracked.type() != CV_8UC1) return;
  next_stamp_ = frame.stamp + Duration::from_seconds(1.0 / config_.publish.image_rate_hz);
  {
    std::lock_guard lock(mutex_);
    if (full_) ++counters_.replaced;
    tracked.copyTo(pending_grey_);  // reuses the buffer: same size every frame
    pending_frame_ = frame;
    full_ = true;
  }
  wake_.notify_one();
}

void ImageOutput::run() {
  cv::Mat grey;
  vision::FrontendFrame frame;
  std::vector<std::uint8_t> jpeg;
  const std::vector<int> params = {cv::IMWRITE_JPEG_QUALITY, 80};
  dds::ImageMessage msg;
  msg.frame_id = config_.dds.camera_frame;  // features are in the visible image's geometry
  msg.format = "jpeg";
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stopping_ || full_; });
    if (!full_) return;  // stopping, nothing left
    cv::swap(grey, pending_grey_);
    std::swap(frame, pending_frame_);
    full_ = false;
    lock.unlock();
    // Outside the lock: the fusion thread copies the next frame while this one is encoded.
    const auto began = std::chrono::steady_clock::now();
    bool ok = cv::imencode(".jpg", vision::feature_overlay(grey, frame), jpeg, params);
    const double encode_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - began).count();
    if (ok) {
      msg.stamp = to_wall_(frame.stamp);
      msg.data.swap(jpeg);
      ok = publisher_.publish_image(msg);
      msg.data.swap(jpeg);
    }
    lock.lock();
    counters_.encode_ms_total += encode_ms;
    if (ok) {
      ++counters_.images;
      counters_.last_bytes = jpeg.size();
    } else {
      ++counters_.failed;
    }
  }
}

ImageOutputCounters ImageOutput::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

}  // namespace posed
