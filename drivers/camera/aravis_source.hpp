#pragma once
// A GenICam camera (GigE Vision or USB3 Vision: the PLUG 617 in GenICam mode) through Aravis, as
// a Source. Aravis reassembles the GVSP/U3V stream into buffers; posed preallocates
// `buffer_count` of them at open and cycles them: a buffer popped by read() is pushed back to
// the stream on the next read(), so the bytes a RawChunk points at stay valid until then.
// A frame with missing packets (GigE loss with resend off or exhausted) is delivered with
// AravisFrameStatus::kMissingPackets: a partial frame is a status, not an error.
// Aravis/GLib headers stay in the .cpp (pimpl).

#include <atomic>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/time.hpp"
#include "drivers/camera/pixel_formats.hpp"
#include "drivers/common/source.hpp"

namespace posed::drivers::camera {

struct AravisConfig {
  /// Aravis device id ("<vendor>-<serial>", e.g. "Aravis-GV01", or an IP address); empty = first
  std::string camera_id;
  /// GenICam PixelFormat: "Mono8" or "Mono16"
  std::string pixel_format = "Mono16";
  std::uint32_t width = 640;       ///< region width [px]; 0 keeps the camera's
  std::uint32_t height = 512;      ///< region height [px]; 0 keeps the camera's
  double frame_rate_hz = 25.0;     ///< AcquisitionFrameRate [Hz]; <= 0 keeps the camera's
  double exposure_time_us = -1.0;  ///< ExposureTime [us]; < 0 keeps the camera's
  double gain_db = -1.0;           ///< Gain [dB]; < 0 keeps the camera's
  /// further GenICam features, applied in order as "Name=Value"
  /// (arv_device_set_features_from_string)
  std::vector<std::string> features;
  std::uint32_t buffer_count = 8;  ///< preallocated stream buffers
  /// GigE: ask the camera to resend lost packets (off: a loss is reported at once)
  bool packet_resend = true;
  /// GigE: GevSCPSPacketSize [B]; 0 lets Aravis negotiate the largest that passes
  std::uint32_t packet_size_bytes = 0;
  /// wait between reopen attempts after the camera was lost [ms]
  int reopen_interval_ms = 1000;
};

enum class AravisFrameStatus : std::uint8_t {
  kComplete,        ///< ARV_BUFFER_STATUS_SUCCESS
  kMissingPackets,  ///< ARV_BUFFER_STATUS_MISSING_PACKETS: partial frame
  kTimeout,         ///< ARV_BUFFER_STATUS_TIMEOUT: the frame's packets stopped arriving
  kOther,           ///< wrong packet id, size mismatch, aborted ...
};
std::string_view to_string(AravisFrameStatus s);

/// The frame behind the last kData.
struct AravisFrame {
  AravisFrameStatus status = AravisFrameStatus::kComplete;
  std::uint64_t frame_id = 0;        ///< GVSP block id / U3V frame counter
  std::uint64_t dropped_before = 0;  ///< frames missing just before this one (frame id gap)
  /// camera timestamp (GevTimestamp ticks as Aravis scales them) [ns]; 0 if the camera has none
  DeviceTime device_stamp;
  HostTime host_receive;     ///< host CLOCK_MONOTONIC when popped
  std::uint32_t width = 0;   ///< [px]
  std::uint32_t height = 0;  ///< [px]
  WireFormat format = WireFormat::kY16;
};

struct AravisCounters {
  std::uint64_t complete = 0;
  std::uint64_t incomplete = 0;  ///< frames delivered with a status other than kComplete
  std::uint64_t dropped = 0;     ///< frame id gaps
  std::uint64_t lost = 0;        ///< control connection lost
  std::uint64_t reopened = 0;
};

/// One discovered GenICam device, for `posectl inspect camera`.
struct AravisDeviceInfo {
  std::string id, vendor, model, serial, protocol, address;
  std::vector<std::string> pixel_formats;  ///< empty when the camera could not be opened
};
/// Lists GenICam devices (GigE Vision, USB3 Vision; plus Aravis's Fake interface when
/// `include_fake`). Opens each to read its pixel formats when `with_formats`.
std::vector<AravisDeviceInfo> list_aravis_devices(bool with_formats, bool include_fake = false);

class AravisSource final : public Source {
 public:
  AravisSource(std::string name, AravisConfig config);
  ~AravisSource() override;
  std::string_view name() const override { return name_; }
  /// the negotiated pixel format (valid after open())
  std::string_view wire_format(std::uint32_t channel) const override {
    return channel == 0 ? to_string(format_) : std::string_view{};
  }
  bool open(std::string& error) override;
  ReadStatus read(RawChunk& chunk, Duration timeout) override;
  void request_stop() override { stop_.store(true, std::memory_order_relaxed); }
  SourceCounters counters() const override;

  const AravisFrame& last_frame() const { return frame_; }
  const AravisCounters& frame_counters() const { return frame_counters_; }
  /// negotiated geometry and format, valid after open()
  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }
  WireFormat format() const { return format_; }

  struct Impl;

 private:
  void close();
  std::string name_;
  AravisConfig config_;
  std::unique_ptr<Impl> impl_;
  AravisFrame frame_;
  AravisCounters frame_counters_;
  std::uint32_t width_ = 0, height_ = 0;
  WireFormat format_ = WireFormat::kY16;
  bool have_frame_id_ = false;
  std::uint64_t last_frame_id_ = 0;
  std::atomic<bool> stop_{false};
  AtomicSourceCounters counts_;
};

}  // namespace posed::drivers::camera
