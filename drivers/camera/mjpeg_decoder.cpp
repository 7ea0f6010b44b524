#include "drivers/camera/mjpeg_decoder.hpp"

#include <turbojpeg.h>

namespace posed::drivers::camera {
namespace {

int tj_pixel_format(PixelFormat f) {
  switch (f) {
    case PixelFormat::kBgr8:
      return TJPF_BGR;
    case PixelFormat::kRgb8:
      return TJPF_RGB;
    case PixelFormat::kMono8:
      return TJPF_GRAY;
    default:
      return -1;
  }
}

}  // namespace

MjpegDecoder::MjpegDecoder() : handle_(tjInitDecompress()) {}

MjpegDecoder::~MjpegDecoder() {
  if (handle_ != nullptr) tjDestroy(static_cast<tjhandle>(handle_));
}

void MjpegDecoder::reset_handle() {
  // After a failed header or decode, libjpeg's state inside the handle may be stale (a later
  // header read of a cut stream then reports the previous image's size); a fresh handle costs an
  // allocation only on this error path.
  if (handle_ != nullptr) tjDestroy(static_cast<tjhandle>(handle_));
  handle_ = tjInitDecompress();
}

bool MjpegDecoder::peek_size(std::span<const std::byte> jpeg, std::uint32_t& width,
                             std::uint32_t& height) {
  if (handle_ == nullptr || jpeg.empty()) return false;
  int w = 0, h = 0, subsamp = 0, colorspace = 0;
  if (tjDecompressHeader3(
          static_cast<tjhandle>(handle_), reinterpret_cast<const unsigned char*>(jpeg.data()),
          static_cast<unsigned long>(jpeg.size()), &w, &h, &subsamp, &colorspace) != 0 ||
      w <= 0 || h <= 0) {
    reset_handle();
    return false;
  }
  width = static_cast<std::uint32_t>(w);
  height = static_cast<std::uint32_t>(h);
  return true;
}

ConvertStatus MjpegDecoder::decode(std::span<const std::byte> jpeg, std::uint32_t width,
                                   std::uint32_t height, ImageSpan dst, PixelFormat out) {
  const int pf = tj_pixel_format(out);
  if (handle_ == nullptr || pf < 0) {
    ++counters_.errors;
    return ConvertStatus::kUnsupported;
  }
  std::uint32_t w = 0, h = 0;
  if (!peek_size(jpeg, w, h)) {
    ++counters_.errors;
    return ConvertStatus::kDecodeError;
  }
  if (w != width || h != height) {
    ++counters_.size_mismatch;
    return ConvertStatus::kBadGeometry;
  }
  const std::uint64_t row = static_cast<std::uint64_t>(width) * tjPixelSize[pf];
  const std::uint64_t stride = dst.stride_bytes != 0 ? dst.stride_bytes : row;
  if (stride < row || stride * (height - 1) + row > dst.bytes.size()) {
    ++counters_.errors;
    return ConvertStatus::kBadGeometry;
  }
  const int rc = tjDecompress2(
      static_cast<tjhandle>(handle_), reinterpret_cast<const unsigned char*>(jpeg.data()),
      static_cast<unsigned long>(jpeg.size()), reinterpret_cast<unsigned char*>(dst.bytes.data()),
      static_cast<int>(width), static_cast<int>(stride), static_cast<int>(height), pf, 0);
  if (rc == 0) {
    ++counters_.frames;
    return ConvertStatus::kOk;
  }
  // TurboJPEG reports recoverable problems (premature end of data, corrupt entropy) as
  // TJERR_WARNING with the image still written: a partial frame, not an error.
  const bool warning = tjGetErrorCode(static_cast<tjhandle>(handle_)) == TJERR_WARNING;
  reset_handle();
  if (warning) {
    ++counters_.partial;
    return ConvertStatus::kTruncated;
  }
  ++counters_.errors;
  return ConvertStatus::kDecodeError;
}

bool encode_jpeg(std::span<const std::byte> src, std::uint32_t width, std::uint32_t height,
                          PixelFormat format, int quality, std::vector<std::byte>& out) {
  const int pf = tj_pixel_format(format);
  if (pf < 0) return false;
  tjhandle h = tjInitCompress();
  if (h == nullptr) return false;
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  const int rc = tjCompress2(h, reinterpret_cast<const unsigned char*>(src.data()),
                             static_cast<int>(width), 0, static_cast<int>(height), pf, &jpeg, &size,
                             pf == TJPF_GRAY ? TJSAMP_GRAY : TJSAMP_422, quality, 0);
  if (rc == 0) {
    out.assign(reinterpret_cast<const std::byte*>(jpeg),
               reinterpret_cast<const std::byte*>(jpeg) + size);
  }
  tjFree(jpeg);
  tjDestroy(h);
  return rc == 0;
}

}  // namespace posed::drivers::camera
