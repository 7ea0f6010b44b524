#pragma once
// MJPEG frames (UVC: one baseline JPEG per frame, often without Huffman tables, which libjpeg-turbo
// supplies) decoded with libjpeg-turbo's TurboJPEG API. The handle is created once and reused, so
// steady-state decoding allocates nothing. turbojpeg.h stays in the .cpp.

#include <cstdint>
#include <span>
#include <vector>

#include "core/measurements.hpp"
#include "drivers/camera/pixel_formats.hpp"

namespace posed::drivers::camera {

struct MjpegCounters {
  std::uint64_t frames = 0;         ///< frames decoded completely
  std::uint64_t partial = 0;        ///< frames decoded with a libjpeg warning (corrupt/short data)
  std::uint64_t errors = 0;         ///< frames that could not be decoded
  std::uint64_t size_mismatch = 0;  ///< JPEG header size differs from the negotiated size
};

class MjpegDecoder {
 public:
  MjpegDecoder();
  ~MjpegDecoder();
  MjpegDecoder(const MjpegDecoder&) = delete;
  MjpegDecoder& operator=(const MjpegDecoder&) = delete;

  /// Decodes one JPEG of `width` x `height` into `dst` as `out` (kBgr8, kRgb8 or kMono8).
  /// A JPEG of another size is kBadGeometry (counted); corrupt data that still decodes is
  /// kTruncated; undecodable data is kDecodeError. Never throws.
  ConvertStatus decode(std::span<const std::byte> jpeg, std::uint32_t width, std::uint32_t height,
                       ImageSpan dst, PixelFormat out = PixelFormat::kBgr8);

  /// Reads the size from a JPEG header without decoding; false if the header is unreadable.
  bool peek_size(std::span<const std::byte> jpeg, std::uint32_t& width, std::uint32_t& height);

  const MjpegCounters& counters() const { return counters_; }

 private:
  void reset_handle();
  void* handle_ = nullptr;  // tjhandle
  MjpegCounters counters_;
};

/// Encodes `src` (kBgr8 or kMono8, rows packed) as a JPEG into `out` (resized): rt/posed/image/
/// compressed, and tests and benchmarks that need real MJPEG frames. Returns false on failure.
/// libturbojpeg, as the decoder, so posed needs no image codec library beyond it.
bool encode_jpeg(std::span<const std::byte> src, std::uint32_t width, std::uint32_t height,
                 PixelFormat format, int quality, std::vector<std::byte>& out);

}  // namespace posed::drivers::camera
