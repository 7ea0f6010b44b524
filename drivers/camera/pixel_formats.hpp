#pragma once
// Wire pixel formats the cameras deliver (V4L2 fourccs, GenICam PFNC) and their pure conversion
// into the core image formats (core/measurements.hpp). No I/O, no allocation, never throws: a
// short or malformed frame is a status, and the rows that did arrive are still converted.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/measurements.hpp"

namespace posed::drivers::camera {

/// V4L2 fourcc code as in linux/videodev2.h (v4l2_fourcc: little-endian a,b,c,d).
constexpr std::uint32_t fourcc(char a, char b, char c, char d) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(a)) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(b)) << 8) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(c)) << 16) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(d)) << 24);
}

/// The formats posed decodes. The D435i colour node gives YUYV (also UYVY/RGB8/BGR8), the depth
/// node Z16; the PLUG 617 gives MJPEG/YUYV (8-bit AGC'd, as M2DGR recorded it) or Y16 raw counts.
enum class WireFormat : std::uint8_t {
  kYuyv,   ///< 4:2:2 Y0 U Y1 V, BT.601 limited range (V4L2_PIX_FMT_YUYV)
  kUyvy,   ///< 4:2:2 U Y0 V Y1 (V4L2_PIX_FMT_UYVY)
  kRgb8,   ///< packed R,G,B (V4L2_PIX_FMT_RGB24)
  kBgr8,   ///< packed B,G,R (V4L2_PIX_FMT_BGR24)
  kMjpeg,  ///< one JPEG per frame (V4L2_PIX_FMT_MJPEG)
  kZ16,    ///< 16-bit depth, little-endian, device depth units (V4L2_PIX_FMT_Z16)
  kY8,     ///< 8-bit grey (V4L2_PIX_FMT_GREY)
  kY16,    ///< 16-bit grey, little-endian (V4L2_PIX_FMT_Y16)
};

std::string_view to_string(WireFormat f);
/// Parses "yuyv", "uyvy", "rgb8", "bgr8", "mjpeg", "z16", "y8", "y16" (as in configs).
std::optional<WireFormat> wire_format_from_string(std::string_view s);
/// The V4L2 fourcc of a wire format.
std::uint32_t to_fourcc(WireFormat f);
/// The wire format of a V4L2 fourcc; nullopt for formats posed does not decode.
std::optional<WireFormat> wire_format_from_fourcc(std::uint32_t fourcc);
/// The fourcc as four printable characters ("YUYV"), for logs.
std::string fourcc_to_string(std::uint32_t fourcc);

/// The core format a wire format decodes to: colour -> BGR8 (RGB8 stays RGB8), Z16 -> depth16,
/// Y8 -> mono8, Y16 -> mono16.
PixelFormat decoded_format(WireFormat f);
/// Bytes per pixel on the wire for uncompressed formats; 0 for MJPEG.
int wire_bytes_per_pixel(WireFormat f);

enum class ConvertStatus : std::uint8_t {
  kOk,
  kTruncated,    ///< the source held fewer bytes than a full frame; the rows present were
                 ///< converted and the rest zeroed (a partial frame, not an error)
  kBadGeometry,  ///< width/height/strides inconsistent or the destination too small
  kDecodeError,  ///< compressed data could not be decoded (MJPEG)
  kUnsupported,  ///< no decoder for this format here (MJPEG goes through MjpegDecoder)
};
std::string_view to_string(ConvertStatus s);

/// Source frame: bytes as the device delivered them.
struct FrameView {
  std::span<const std::byte> bytes;  ///< frame payload (bytesused)
  std::uint32_t width = 0;           ///< [px]
  std::uint32_t height = 0;          ///< [px]
  /// bytes per source row [B]; 0 = packed (width * wire bytes per pixel)
  std::uint32_t stride_bytes = 0;
  WireFormat format = WireFormat::kYuyv;
};

/// Destination: a pool buffer (or any memory) that receives decoded_format(src.format).
struct ImageSpan {
  std::span<std::byte> bytes;
  /// bytes per destination row [B]; 0 = packed
  std::uint32_t stride_bytes = 0;
};

/// Converts one uncompressed frame (everything but MJPEG) into `dst`, written as
/// decoded_format(src.format) with the same width and height.
ConvertStatus convert_frame(const FrameView& src, ImageSpan dst);

// The individual kernels, exposed for the benchmark and tests. Strides in bytes.
/// YUYV/UYVY -> BGR8 with the BT.601 limited-range integer coefficients OpenCV uses
/// (modules/imgproc/src/color_yuv.simd.hpp: ITUR_BT_601_CY = 1220542 etc., 20-bit fixed point).
void yuv422_to_bgr(const std::uint8_t* src, std::uint32_t src_stride, std::uint8_t* dst,
                   std::uint32_t dst_stride, std::uint32_t width, std::uint32_t rows, bool uyvy);
/// Copies rows of `row_bytes`, little-endian 16-bit samples turned into host order.
void copy_rows_u16le(const std::uint8_t* src, std::uint32_t src_stride, std::uint8_t* dst,
                     std::uint32_t dst_stride, std::uint32_t width, std::uint32_t rows);

/// Fills an Image's geometry fields for a decoded frame (pixels/stamps are the caller's).
void set_image_geometry(Image& image, std::uint32_t width, std::uint32_t height,
                        PixelFormat format);

}  // namespace posed::drivers::camera
