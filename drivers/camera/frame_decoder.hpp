#pragma once
// Turns one camera frame's bytes (from a live V4L2/Aravis Source or a recording) into a core
// Image whose pixels live in a PayloadPool buffer: the decode writes straight into the pool
// buffer, so the device's buffer is read once and never copied elsewhere. Pure (no I/O), never
// throws; a pool with no free buffer or a bad frame is a status with a counter.

#include <cstdint>
#include <memory>
#include <span>

#include "core/measurements.hpp"
#include "core/payload_pool.hpp"
#include "drivers/camera/mjpeg_decoder.hpp"
#include "drivers/camera/pixel_formats.hpp"
#include "drivers/camera/thermal_agc.hpp"

namespace posed::drivers::camera {

struct FrameDecoderConfig {
  WireFormat format = WireFormat::kYuyv;
  std::uint32_t width = 640;   ///< [px]
  std::uint32_t height = 480;  ///< [px]
  /// source bytes per row [B]; 0 = packed
  std::uint32_t stride_bytes = 0;
  /// Y16 only: emit 8-bit through AGC (mono8) instead of raw counts (mono16)
  bool y16_agc_to_mono8 = false;
  AgcConfig agc;
  /// MJPEG only: decode to mono8 (thermal) instead of bgr8
  bool mjpeg_to_mono8 = false;
  /// Z16 only: metres per depth unit (D435i default 0.001) [m]
  float depth_unit_m = 0.001f;
};

enum class DecodeStatus : std::uint8_t {
  kOk,
  kPartial,       ///< decoded, but the frame was short/corrupt (rows missing are zero)
  kPoolEmpty,     ///< no free pool buffer: the frame is dropped (consumer too slow)
  kPoolTooSmall,  ///< pool buffers smaller than one decoded frame (configuration error)
  kBadFrame,      ///< undecodable
};

struct FrameDecoderCounters {
  std::uint64_t ok = 0;
  std::uint64_t partial = 0;
  std::uint64_t pool_empty = 0;
  std::uint64_t bad = 0;
};

class FrameDecoder {
 public:
  explicit FrameDecoder(FrameDecoderConfig config);
  /// The format of the Images produced.
  PixelFormat output_format() const;
  /// Bytes one decoded frame needs in a pool buffer [B].
  std::size_t output_bytes() const;
  /// Decodes `bytes` into `out` (pixels, geometry, sequence; stamps are the caller's).
  DecodeStatus decode(std::span<const std::byte> bytes, std::uint64_t sequence, PayloadPool& pool,
                      Image& out);
  const FrameDecoderCounters& counters() const { return counters_; }

 private:
  FrameDecoderConfig config_;
  std::unique_ptr<MjpegDecoder> mjpeg_;
  std::unique_ptr<ThermalAgc> agc_;
  FrameDecoderCounters counters_;
};

}  // namespace posed::drivers::camera
