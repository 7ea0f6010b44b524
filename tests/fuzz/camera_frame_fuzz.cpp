// libFuzzer target: one camera frame as V4L2/Aravis (or a recording) delivers it, through
// FrameDecoder: the pixel format kernels, thermal AGC and MJPEG via libjpeg-turbo. The first 8
// bytes say what the Source negotiated, the rest is the frame:
//   byte 0     wire format (WireFormat, modulo the number of formats)
//   byte 1     bit 0 Y16 through AGC to mono8, bit 1 MJPEG to mono8, bit 2 AGC histogram mode
//   bytes 2-3  width [px], 4-5 height [px], 6-7 source stride [B] (0 packed), little-endian
// Contracts beyond "no crash, no UB": each frame is counted exactly once, an Image handed out has
// the negotiated geometry and its pixels, and a frame the pool cannot hold is refused, not cut.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "core/payload_pool.hpp"
#include "drivers/camera/frame_decoder.hpp"

namespace cam = posed::drivers::camera;

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

std::uint16_t u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | static_cast<unsigned>(p[1]) << 8);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 8) return 0;
  // 1 MiB buffers: a 640x480 BGR frame fits, larger negotiated sizes meet kPoolTooSmall (and the
  // zero fill of a short frame stays cheap).
  static posed::PayloadPool pool(2, 1u << 20);
  cam::FrameDecoderConfig config;
  config.format = static_cast<cam::WireFormat>(data[0] % 8);
  config.y16_agc_to_mono8 = (data[1] & 1) != 0;
  config.mjpeg_to_mono8 = (data[1] & 2) != 0;
  config.agc.mode =
      (data[1] & 4) != 0 ? cam::AgcMode::kHistogramEqualisation : cam::AgcMode::kPercentileStretch;
  config.width = u16(data + 2);
  config.height = u16(data + 4);
  config.stride_bytes = u16(data + 6);
  const auto frame = std::span(reinterpret_cast<const std::byte*>(data) + 8, size - 8);

  cam::FrameDecoder decoder(config);
  posed::Image image;
  const cam::DecodeStatus s = decoder.decode(frame, 7, pool, image);
  const cam::FrameDecoderCounters& c = decoder.counters();
  check(c.ok + c.partial + c.pool_empty + c.bad == 1);
  if (s == cam::DecodeStatus::kOk || s == cam::DecodeStatus::kPartial) {
    check(image.pixels.valid() && image.width == config.width && image.height == config.height);
    check(image.width > 0 && image.height > 0);  // an empty frame is not a frame
    check(image.format == decoder.output_format());
    check(static_cast<std::size_t>(image.stride) * image.height <= pool.buffer_bytes());
    // Touch the last pixel row: it lies inside the pool buffer.
    const auto px = image.pixels.bytes();
    volatile std::byte sink = px[static_cast<std::size_t>(image.stride) * image.height - 1];
    (void)sink;
  } else {
    check(!image.pixels.valid());
    if (s == cam::DecodeStatus::kPoolTooSmall) check(decoder.output_bytes() > pool.buffer_bytes());
  }
  check(pool.in_use() == (image.pixels.valid() ? 1u : 0u));
  return 0;
}
