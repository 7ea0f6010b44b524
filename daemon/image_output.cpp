#include "daemon/image_output.hpp"

#include <chrono>
#include <utility>
#include <vector>

#include "core/vision/feature_overlay.hpp"
#include "core/vision/visual_frontend.hpp"
#include "daemon/dds/publisher.hpp"
#include "drivers/camera/mjpeg_decoder.hpp"

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
  std::vector<std::byte> jpeg;
  cv::Mat overlay;
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
    // Outside the lock: the front end's thread copies the next frame while this one is encoded.
    const auto began = std::chrono::steady_clock::now();
    // libturbojpeg (as the MJPEG decoder), not OpenCV's imgcodecs: linking that into posed
    // brings codec libraries whose start-up calls fall outside the unit's system-call filter.
    overlay = vision::feature_overlay(grey, frame);
    bool ok = overlay.isContinuous() &&
              drivers::camera::encode_jpeg(
                  {reinterpret_cast<const std::byte*>(overlay.data), overlay.total() * 3},
                  static_cast<std::uint32_t>(overlay.cols),
                  static_cast<std::uint32_t>(overlay.rows), PixelFormat::kBgr8, 80, jpeg);
    const double encode_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - began).count();
    if (ok) {
      msg.stamp = to_wall_(frame.stamp);
      const auto* bytes = reinterpret_cast<const std::uint8_t*>(jpeg.data());
      msg.data.assign(bytes, bytes + jpeg.size());
      ok = publisher_.publish_image(msg);
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
