#include "drivers/camera/frame_decoder.hpp"

namespace posed::drivers::camera {

FrameDecoder::FrameDecoder(FrameDecoderConfig config) : config_(config) {
  if (config_.format == WireFormat::kMjpeg) mjpeg_ = std::make_unique<MjpegDecoder>();
  if (config_.format == WireFormat::kY16 && config_.y16_agc_to_mono8) {
    agc_ = std::make_unique<ThermalAgc>(config_.agc);
  }
}

PixelFormat FrameDecoder::output_format() const {
  if (agc_) return PixelFormat::kMono8;
  if (mjpeg_ && config_.mjpeg_to_mono8) return PixelFormat::kMono8;
  return decoded_format(config_.format);
}

std::size_t FrameDecoder::output_bytes() const {
  return static_cast<std::size_t>(config_.width) * config_.height *
         static_cast<std::size_t>(bytes_per_pixel(output_format()));
}

DecodeStatus FrameDecoder::decode(std::span<const std::byte> bytes, std::uint64_t sequence,
                                  PayloadPool& pool, Image& out) {
  if (pool.buffer_bytes() < output_bytes()) {
    ++counters_.bad;
    return DecodeStatus::kPoolTooSmall;
  }
  PayloadPool::Lease lease = pool.acquire();
  if (!lease) {
    ++counters_.pool_empty;
    return DecodeStatus::kPoolEmpty;
  }
  set_image_geometry(out, config_.width, config_.height, output_format());
  out.sequence = sequence;
  out.depth_unit_m = config_.depth_unit_m;
  const ImageSpan dst{lease.bytes(), out.stride};
  ConvertStatus s;
  if (mjpeg_) {
    s = mjpeg_->decode(bytes, config_.width, config_.height, dst, output_format());
  } else if (agc_) {
    // AGC needs whole 16-bit samples in host order; the wire is little-endian like the host
    // (x86/arm64), so the pixels are read in place. A short frame is dropped rather than
    // stretched: its histogram (and so the gain) would be wrong.
    const std::size_t row = static_cast<std::size_t>(config_.width) * 2;
    const std::size_t stride = config_.stride_bytes != 0 ? config_.stride_bytes : row;
    if (config_.width == 0 || config_.height == 0 || stride < row || stride % 2 != 0) {
      // As convert_frame refuses them; an odd stride would also misalign every other row.
      s = ConvertStatus::kBadGeometry;
    } else if (bytes.size() < stride * (config_.height - 1) + row ||
               reinterpret_cast<std::uintptr_t>(bytes.data()) % 2 != 0) {
      s = ConvertStatus::kDecodeError;
    } else {
      agc_->apply(reinterpret_cast<const std::uint16_t*>(bytes.data()),
                  static_cast<std::uint32_t>(stride),
                  reinterpret_cast<std::uint8_t*>(lease.bytes().data()), out.stride, config_.width,
                  config_.height);
      s = ConvertStatus::kOk;
    }
  } else {
    s = convert_frame({bytes, config_.width, config_.height, config_.stride_bytes, config_.format},
                      dst);
  }
  switch (s) {
    case ConvertStatus::kOk:
      ++counters_.ok;
      out.pixels = std::move(lease);
      return DecodeStatus::kOk;
    case ConvertStatus::kTruncated:
      ++counters_.partial;
      out.pixels = std::move(lease);
      return DecodeStatus::kPartial;
    default:
      ++counters_.bad;
      return DecodeStatus::kBadFrame;
  }
}

}  // namespace posed::drivers::camera
