#include "drivers/camera/aravis_source.hpp"

#include <arv.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"

#if defined(__SANITIZE_THREAD__)
extern "C" void __tsan_acquire(void* addr);
extern "C" void __tsan_release(void* addr);
#endif

namespace posed::drivers::camera {

struct AravisSource::Impl {
  ArvCamera* camera = nullptr;
  ArvStream* stream = nullptr;
  ArvBuffer* held = nullptr;  // popped, pushed back on the next read
  std::atomic<bool> control_lost{false};
  bool lost = false;  // closed after a loss; read() reopens
};

namespace {

/// Takes a GError's message (and frees it); "" when none.
std::string take_error(GError*& e) {
  if (e == nullptr) return {};
  std::string m = e->message != nullptr ? e->message : "unknown error";
  g_clear_error(&e);
  return m;
}

// A buffer passes between Aravis's stream thread and read() through GLib's queue, whose futexes
// ThreadSanitizer cannot see (GLib is not built with it): without telling it, the thread that
// filled a frame and the one that decodes it look like a race. The hand-overs are announced here,
// on the buffer's address, in both directions; outside TSan builds these do nothing.
void announce_handed_over(ArvBuffer* buffer) {
#if defined(__SANITIZE_THREAD__)
  __tsan_release(buffer);
#else
  (void)buffer;
#endif
}

void announce_taken_over(ArvBuffer* buffer) {
#if defined(__SANITIZE_THREAD__)
  __tsan_acquire(buffer);
#else
  (void)buffer;
#endif
}

/// Aravis's stream thread: it takes a buffer read() gave back, and gives it filled.
void on_stream_event(void* /*user*/, ArvStreamCallbackType type, ArvBuffer* buffer) {
  if (buffer == nullptr) return;
  if (type == ARV_STREAM_CALLBACK_TYPE_START_BUFFER) announce_taken_over(buffer);
  if (type == ARV_STREAM_CALLBACK_TYPE_BUFFER_DONE) announce_handed_over(buffer);
}

void on_control_lost(ArvDevice* /*device*/, gpointer user) {
  // Emitted from Aravis's heartbeat thread: only flag it; read() closes and reopens.
  static_cast<AravisSource::Impl*>(user)->control_lost.store(true, std::memory_order_relaxed);
}

AravisFrameStatus map_status(ArvBufferStatus s) {
  switch (s) {
    case ARV_BUFFER_STATUS_SUCCESS:
      return AravisFrameStatus::kComplete;
    case ARV_BUFFER_STATUS_MISSING_PACKETS:
      return AravisFrameStatus::kMissingPackets;
    case ARV_BUFFER_STATUS_TIMEOUT:
      return AravisFrameStatus::kTimeout;
    default:
      return AravisFrameStatus::kOther;
  }
}

std::string dup_string(const char* s) { return s != nullptr ? s : ""; }

}  // namespace

std::string_view to_string(AravisFrameStatus s) {
  switch (s) {
    case AravisFrameStatus::kComplete:
      return "complete";
    case AravisFrameStatus::kMissingPackets:
      return "missing_packets";
    case AravisFrameStatus::kTimeout:
      return "timeout";
    case AravisFrameStatus::kOther:
      return "other";
  }
  return "unknown";
}

std::vector<AravisDeviceInfo> list_aravis_devices(bool with_formats, bool include_fake) {
  if (include_fake) arv_enable_interface("Fake");
  arv_update_device_list();
  std::vector<AravisDeviceInfo> out;
  const unsigned n = arv_get_n_devices();
  for (unsigned i = 0; i < n; ++i) {
    AravisDeviceInfo d;
    d.id = dup_string(arv_get_device_id(i));
    d.vendor = dup_string(arv_get_device_vendor(i));
    d.model = dup_string(arv_get_device_model(i));
    d.serial = dup_string(arv_get_device_serial_nbr(i));
    d.protocol = dup_string(arv_get_device_protocol(i));
    d.address = dup_string(arv_get_device_address(i));
    if (with_formats) {
      GError* e = nullptr;
      ArvCamera* cam = arv_camera_new(d.id.c_str(), &e);
      if (cam != nullptr) {
        guint count = 0;
        const char** fmts = arv_camera_dup_available_pixel_formats_as_strings(cam, &count, &e);
        for (guint k = 0; fmts != nullptr && k < count; ++k) d.pixel_formats.push_back(fmts[k]);
        g_free(fmts);
        g_object_unref(cam);
      }
      g_clear_error(&e);
    }
    out.push_back(std::move(d));
  }
  return out;
}

AravisSource::AravisSource(std::string name, AravisConfig config)
    : name_(std::move(name)), config_(std::move(config)), impl_(std::make_unique<Impl>()) {}

AravisSource::~AravisSource() { close(); }

void AravisSource::close() {
  if (impl_->camera == nullptr) return;
  GError* e = nullptr;
  arv_camera_stop_acquisition(impl_->camera, &e);
  g_clear_error(&e);
  if (impl_->held != nullptr) {
    g_object_unref(impl_->held);
    impl_->held = nullptr;
  }
  // Unreffing the stream stops its receiving thread and frees the buffers it still owns.
  g_clear_object(&impl_->stream);
  g_clear_object(&impl_->camera);
}

bool AravisSource::open(std::string& error) {
  if (impl_->camera != nullptr) return true;
  const std::string who = "genicam camera '" + config_.camera_id + "'";
  GError* e = nullptr;
  impl_->camera =
      arv_camera_new(config_.camera_id.empty() ? nullptr : config_.camera_id.c_str(), &e);
  if (impl_->camera == nullptr) {
    error = who + ": not found or not reachable: " + take_error(e);
    return false;
  }
  ArvCamera* cam = impl_->camera;
  auto fail = [&](const std::string& what) {
    error = who + ": " + what + ": " + take_error(e);
    close();
    return false;
  };
  arv_camera_set_pixel_format_from_string(cam, config_.pixel_format.c_str(), &e);
  if (e != nullptr) return fail("PixelFormat=" + config_.pixel_format);
  if (config_.width > 0 && config_.height > 0) {
    arv_camera_set_region(cam, 0, 0, static_cast<gint>(config_.width),
                          static_cast<gint>(config_.height), &e);
    if (e != nullptr)
      return fail("region " + std::to_string(config_.width) + "x" + std::to_string(config_.height));
  }
  if (config_.frame_rate_hz > 0) {
    arv_camera_set_frame_rate(cam, config_.frame_rate_hz, &e);
    if (e != nullptr) return fail("AcquisitionFrameRate");
  }
  if (config_.exposure_time_us >= 0) {
    arv_camera_set_exposure_time(cam, config_.exposure_time_us, &e);
    if (e != nullptr) return fail("ExposureTime");
  }
  if (config_.gain_db >= 0) {
    arv_camera_set_gain(cam, config_.gain_db, &e);
    if (e != nullptr) return fail("Gain");
  }
  ArvDevice* device = arv_camera_get_device(cam);
  for (const auto& f : config_.features) {
    if (!arv_device_set_features_from_string(device, f.c_str(), &e)) return fail("feature " + f);
  }
  if (arv_camera_is_gv_device(cam)) {
    if (config_.packet_size_bytes > 0) {
      arv_camera_gv_set_packet_size(cam, static_cast<gint>(config_.packet_size_bytes), &e);
    } else {
      arv_camera_gv_auto_packet_size(cam, &e);
    }
    if (e != nullptr) return fail("GevSCPSPacketSize");
  }

  // Read back what the camera agreed to.
  gint x = 0, y = 0, w = 0, h = 0;
  arv_camera_get_region(cam, &x, &y, &w, &h, &e);
  if (e != nullptr) return fail("reading the region");
  const char* pf = arv_camera_get_pixel_format_as_string(cam, &e);
  if (e != nullptr || pf == nullptr) return fail("reading PixelFormat");
  const std::string pf_name = pf;
  if (pf_name == "Mono8") {
    format_ = WireFormat::kY8;
  } else if (pf_name == "Mono16") {
    format_ = WireFormat::kY16;
  } else {
    error = who + ": PixelFormat " + pf_name + " not supported (Mono8, Mono16)";
    close();
    return false;
  }
  width_ = static_cast<std::uint32_t>(w);
  height_ = static_cast<std::uint32_t>(h);
  const guint payload = arv_camera_get_payload(cam, &e);
  if (e != nullptr) return fail("PayloadSize");

  impl_->stream = arv_camera_create_stream(cam, on_stream_event, nullptr, &e);
  if (impl_->stream == nullptr) return fail("creating the stream");
  if (ARV_IS_GV_STREAM(impl_->stream)) {
    g_object_set(impl_->stream, "packet-resend",
                 config_.packet_resend ? ARV_GV_STREAM_PACKET_RESEND_ALWAYS
                                       : ARV_GV_STREAM_PACKET_RESEND_NEVER,
                 nullptr);
  }
  for (std::uint32_t i = 0; i < config_.buffer_count; ++i) {
    ArvBuffer* buffer = arv_buffer_new_allocate(payload);
    announce_handed_over(buffer);
    arv_stream_push_buffer(impl_->stream, buffer);
  }
  impl_->control_lost.store(false);
  g_signal_connect(device, "control-lost", G_CALLBACK(on_control_lost), impl_.get());
  arv_camera_set_acquisition_mode(cam, ARV_ACQUISITION_MODE_CONTINUOUS, &e);
  g_clear_error(&e);  // some cameras only do continuous and reject the write
  arv_camera_start_acquisition(cam, &e);
  if (e != nullptr) return fail("AcquisitionStart");
  have_frame_id_ = false;
  return true;
}

ReadStatus AravisSource::read(RawChunk& chunk, Duration timeout) {
  if (stop_.load(std::memory_order_relaxed)) {
    close();
    return ReadStatus::kEndOfStream;
  }
  if (impl_->lost) {
    const auto wait_ms = std::min<std::int64_t>(timeout.ns / 1'000'000, config_.reopen_interval_ms);
    std::this_thread::sleep_for(std::chrono::milliseconds(std::max<std::int64_t>(0, wait_ms)));
    std::string error;
    if (!open(error)) return ReadStatus::kDeviceLost;
    impl_->lost = false;
    ++frame_counters_.reopened;
    counts_.reopened.fetch_add(1, std::memory_order_relaxed);
    POSED_LOG_NOTICE("%s: genicam camera '%s' reopened", name_.c_str(), config_.camera_id.c_str());
  }
  if (impl_->camera == nullptr) {
    counts_.rejected.fetch_add(1, std::memory_order_relaxed);
    return ReadStatus::kTimeout;  // never opened: the caller opens first
  }
  if (impl_->control_lost.load(std::memory_order_relaxed)) {
    POSED_LOG_WARN("%s: genicam camera '%s': control connection lost (will reopen)", name_.c_str(),
                   config_.camera_id.c_str());
    ++frame_counters_.lost;
    close();
    impl_->lost = true;
    return ReadStatus::kDeviceLost;
  }
  if (impl_->held != nullptr) {
    announce_handed_over(impl_->held);
    arv_stream_push_buffer(impl_->stream, impl_->held);
    impl_->held = nullptr;
  }
  ArvBuffer* buffer = arv_stream_timeout_pop_buffer(
      impl_->stream, static_cast<guint64>(std::max<std::int64_t>(0, timeout.ns / 1000)));
  if (buffer == nullptr) return ReadStatus::kTimeout;
  announce_taken_over(buffer);
  impl_->held = buffer;
  frame_ = {};
  frame_.host_receive = host_now();
  frame_.status = map_status(arv_buffer_get_status(buffer));
  frame_.frame_id = arv_buffer_get_frame_id(buffer);
  frame_.device_stamp =
      DeviceTime::from_ns(static_cast<std::int64_t>(arv_buffer_get_timestamp(buffer)));
  frame_.format = format_;
  frame_.width = width_;
  frame_.height = height_;
  if (frame_.status == AravisFrameStatus::kComplete) {
    frame_.width = static_cast<std::uint32_t>(arv_buffer_get_image_width(buffer));
    frame_.height = static_cast<std::uint32_t>(arv_buffer_get_image_height(buffer));
    ++frame_counters_.complete;
  } else {
    ++frame_counters_.incomplete;
  }
  if (have_frame_id_ && frame_.frame_id > last_frame_id_ + 1) {
    frame_.dropped_before = frame_.frame_id - last_frame_id_ - 1;
    frame_counters_.dropped += frame_.dropped_before;
  }
  have_frame_id_ = true;
  last_frame_id_ = frame_.frame_id;
  size_t size = 0;
  const void* data = arv_buffer_get_data(buffer, &size);
  // Aravis fills a partial buffer's missing packets' ranges with whatever was there; the size is
  // the full payload either way, and frame_.status says how much to trust it.
  chunk.bytes = {static_cast<const std::byte*>(data), data != nullptr ? size : 0};
  chunk.host_receive = frame_.host_receive;
  chunk.channel = 0;
  counts_.count_chunk(chunk.bytes.size());
  return ReadStatus::kData;
}

SourceCounters AravisSource::counters() const { return counts_.snapshot(); }

}  // namespace posed::drivers::camera
