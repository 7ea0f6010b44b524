#include "drivers/camera/pixel_formats.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>

namespace posed::drivers::camera {
namespace {

struct FormatRow {
  WireFormat format;
  std::string_view name;
  std::uint32_t fourcc;
  PixelFormat decoded;
  int wire_bpp;
};

// fourccs from linux/videodev2.h; Z16 is "Z16 " (V4L2_PIX_FMT_Z16, added for RealSense).
constexpr std::array kFormats = {
    FormatRow{WireFormat::kYuyv, "yuyv", fourcc('Y', 'U', 'Y', 'V'), PixelFormat::kBgr8, 2},
    FormatRow{WireFormat::kUyvy, "uyvy", fourcc('U', 'Y', 'V', 'Y'), PixelFormat::kBgr8, 2},
    FormatRow{WireFormat::kRgb8, "rgb8", fourcc('R', 'G', 'B', '3'), PixelFormat::kRgb8, 3},
    FormatRow{WireFormat::kBgr8, "bgr8", fourcc('B', 'G', 'R', '3'), PixelFormat::kBgr8, 3},
    FormatRow{WireFormat::kMjpeg, "mjpeg", fourcc('M', 'J', 'P', 'G'), PixelFormat::kBgr8, 0},
    FormatRow{WireFormat::kZ16, "z16", fourcc('Z', '1', '6', ' '), PixelFormat::kDepth16, 2},
    FormatRow{WireFormat::kY8, "y8", fourcc('G', 'R', 'E', 'Y'), PixelFormat::kMono8, 1},
    FormatRow{WireFormat::kY16, "y16", fourcc('Y', '1', '6', ' '), PixelFormat::kMono16, 2},
};

const FormatRow& row(WireFormat f) {
  for (const auto& r : kFormats) {
    if (r.format == f) return r;
  }
  return kFormats[0];
}

// BT.601 limited range, 20-bit fixed point; the constants are OpenCV's (color_yuv.simd.hpp).
constexpr int kShift = 20;
constexpr int kCY = 1220542;   // 1.164 * 2^20
constexpr int kCVR = 1673527;  // 1.596
constexpr int kCVG = -852492;  // -0.813
constexpr int kCUG = -409993;  // -0.391
constexpr int kCUB = 2116026;  // 2.018
constexpr int kRound = 1 << (kShift - 1);

inline std::uint8_t clamp_u8(int v) {
  return static_cast<std::uint8_t>(v < 0 ? 0 : (v > 255 ? 255 : v));
}

}  // namespace

std::string_view to_string(WireFormat f) { return row(f).name; }

std::optional<WireFormat> wire_format_from_string(std::string_view s) {
  for (const auto& r : kFormats) {
    if (r.name == s) return r.format;
  }
  return std::nullopt;
}

std::uint32_t to_fourcc(WireFormat f) { return row(f).fourcc; }

std::optional<WireFormat> wire_format_from_fourcc(std::uint32_t code) {
  for (const auto& r : kFormats) {
    if (r.fourcc == code) return r.format;
  }
  return std::nullopt;
}

std::string fourcc_to_string(std::uint32_t code) {
  std::string s(4, ' ');
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((code >> (8 * i)) & 0xFF);
    s[static_cast<std::size_t>(i)] = (c >= 32 && c < 127) ? c : '?';
  }
  return s;
}

PixelFormat decoded_format(WireFormat f) { return row(f).decoded; }
int wire_bytes_per_pixel(WireFormat f) { return row(f).wire_bpp; }

std::string_view to_string(ConvertStatus s) {
  switch (s) {
    case ConvertStatus::kOk:
      return "ok";
    case ConvertStatus::kTruncated:
      return "truncated";
    case ConvertStatus::kBadGeometry:
      return "bad_geometry";
    case ConvertStatus::kDecodeError:
      return "decode_error";
    case ConvertStatus::kUnsupported:
      return "unsupported";
  }
  return "unknown";
}

namespace {

/// Per-sample terms of the BT.601 conversion and the final clamp, precomputed once: the inner
/// loop is table loads and adds instead of multiplies and compare chains (the same integers,
/// so the same results; 2.4x faster on one core, posectl bench camera).
struct Yuv422Tables {
  int y[256];   // max(0, Y - 16) * kCY
  int bu[256];  // kRound + kCUB * (U - 128)
  int gu[256];  // kCUG * (U - 128)
  int rv[256];  // kRound + kCVR * (V - 128)
  int gv[256];  // kRound + kCVG * (V - 128)
  /// clamp_u8(i - kClampOffset): every sum >> kShift lies in [-260, 540]
  std::uint8_t clamp[1536];
  static constexpr int kClampOffset = 512;
  Yuv422Tables() {
    for (int i = 0; i < 256; ++i) {
      y[i] = std::max(0, i - 16) * kCY;
      bu[i] = kRound + kCUB * (i - 128);
      gu[i] = kCUG * (i - 128);
      rv[i] = kRound + kCVR * (i - 128);
      gv[i] = kRound + kCVG * (i - 128);
    }
    for (int i = 0; i < 1536; ++i) clamp[i] = clamp_u8(i - kClampOffset);
  }
};

const Yuv422Tables& yuv422_tables() {
  static const Yuv422Tables t;
  return t;
}

}  // namespace

void yuv422_to_bgr(const std::uint8_t* src, std::uint32_t src_stride, std::uint8_t* dst,
                   std::uint32_t dst_stride, std::uint32_t width, std::uint32_t rows, bool uyvy) {
  const int yo = uyvy ? 1 : 0;  // offset of Y0 in a 4-byte macropixel
  const int uo = uyvy ? 0 : 1;  // offset of U
  const std::uint32_t pairs = width / 2;
  const Yuv422Tables& t = yuv422_tables();
  const std::uint8_t* c = t.clamp + Yuv422Tables::kClampOffset;
  for (std::uint32_t r = 0; r < rows; ++r) {
    const std::uint8_t* __restrict s = src + static_cast<std::size_t>(r) * src_stride;
    std::uint8_t* __restrict d = dst + static_cast<std::size_t>(r) * dst_stride;
    for (std::uint32_t p = 0; p < pairs; ++p, s += 4, d += 6) {
      const int u = s[uo];
      const int v = s[uo + 2];
      const int ruv = t.rv[v];
      const int guv = t.gv[v] + t.gu[u];
      const int buv = t.bu[u];
      const int y0 = t.y[s[yo]];
      const int y1 = t.y[s[yo + 2]];
      d[0] = c[(y0 + buv) >> kShift];
      d[1] = c[(y0 + guv) >> kShift];
      d[2] = c[(y0 + ruv) >> kShift];
      d[3] = c[(y1 + buv) >> kShift];
      d[4] = c[(y1 + guv) >> kShift];
      d[5] = c[(y1 + ruv) >> kShift];
    }
  }
}

void copy_rows_u16le(const std::uint8_t* src, std::uint32_t src_stride, std::uint8_t* dst,
                     std::uint32_t dst_stride, std::uint32_t width, std::uint32_t rows) {
  const std::size_t row_bytes = static_cast<std::size_t>(width) * 2;
  for (std::uint32_t r = 0; r < rows; ++r) {
    const std::uint8_t* s = src + static_cast<std::size_t>(r) * src_stride;
    std::uint8_t* d = dst + static_cast<std::size_t>(r) * dst_stride;
    if constexpr (std::endian::native == std::endian::little) {
      std::memcpy(d, s, row_bytes);
    } else {
      for (std::size_t i = 0; i < row_bytes; i += 2) {
        d[i] = s[i + 1];
        d[i + 1] = s[i];
      }
    }
  }
}

void set_image_geometry(Image& image, std::uint32_t width, std::uint32_t height,
                        PixelFormat format) {
  image.width = width;
  image.height = height;
  image.format = format;
  image.stride = width * static_cast<std::uint32_t>(bytes_per_pixel(format));
}

ConvertStatus convert_frame(const FrameView& src, ImageSpan dst) {
  if (src.format == WireFormat::kMjpeg) return ConvertStatus::kUnsupported;
  const auto in_bpp = static_cast<std::uint32_t>(wire_bytes_per_pixel(src.format));
  const auto out_bpp = static_cast<std::uint32_t>(bytes_per_pixel(decoded_format(src.format)));
  if (src.width == 0 || src.height == 0) return ConvertStatus::kBadGeometry;
  const bool yuv = src.format == WireFormat::kYuyv || src.format == WireFormat::kUyvy;
  if (yuv && src.width % 2 != 0) return ConvertStatus::kBadGeometry;
  const std::uint64_t in_row = static_cast<std::uint64_t>(src.width) * in_bpp;
  const std::uint64_t out_row = static_cast<std::uint64_t>(src.width) * out_bpp;
  const std::uint64_t in_stride = src.stride_bytes != 0 ? src.stride_bytes : in_row;
  const std::uint64_t out_stride = dst.stride_bytes != 0 ? dst.stride_bytes : out_row;
  if (in_stride < in_row || out_stride < out_row || in_stride > 0xFFFFFFFFu ||
      out_stride > 0xFFFFFFFFu) {
    return ConvertStatus::kBadGeometry;
  }
  if (out_stride * (src.height - 1) + out_row > dst.bytes.size()) {
    return ConvertStatus::kBadGeometry;
  }
  // Whole rows present: the last row needs only in_row bytes, not a full stride.
  std::uint32_t rows = src.height;
  if (in_stride * (src.height - 1) + in_row > src.bytes.size()) {
    rows = src.bytes.size() < in_row
               ? 0
               : static_cast<std::uint32_t>((src.bytes.size() - in_row) / in_stride + 1);
  }
  const auto* s = reinterpret_cast<const std::uint8_t*>(src.bytes.data());
  auto* d = reinterpret_cast<std::uint8_t*>(dst.bytes.data());
  const auto ss = static_cast<std::uint32_t>(in_stride);
  const auto ds = static_cast<std::uint32_t>(out_stride);
  switch (src.format) {
    case WireFormat::kYuyv:
    case WireFormat::kUyvy:
      yuv422_to_bgr(s, ss, d, ds, src.width, rows, src.format == WireFormat::kUyvy);
      break;
    case WireFormat::kZ16:
    case WireFormat::kY16:
      copy_rows_u16le(s, ss, d, ds, src.width, rows);
      break;
    case WireFormat::kRgb8:
    case WireFormat::kBgr8:
    case WireFormat::kY8:
      for (std::uint32_t r = 0; r < rows; ++r) {
        std::memcpy(d + static_cast<std::size_t>(r) * ds, s + static_cast<std::size_t>(r) * ss,
                    static_cast<std::size_t>(out_row));
      }
      break;
    case WireFormat::kMjpeg:
      return ConvertStatus::kUnsupported;
  }
  if (rows == src.height) return ConvertStatus::kOk;
  for (std::uint32_t r = rows; r < src.height; ++r) {
    std::memset(d + static_cast<std::size_t>(r) * ds, 0, static_cast<std::size_t>(out_row));
  }
  return ConvertStatus::kTruncated;
}

}  // namespace posed::drivers::camera
