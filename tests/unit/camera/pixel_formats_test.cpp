#include "drivers/camera/pixel_formats.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "drivers/camera/mjpeg_decoder.hpp"

namespace posed::drivers::camera {
namespace {

std::vector<std::byte> bytes(std::initializer_list<int> v) {
  std::vector<std::byte> out;
  for (int x : v) out.push_back(static_cast<std::byte>(x));
  return out;
}

std::uint8_t at(const std::vector<std::byte>& v, std::size_t i) {
  return static_cast<std::uint8_t>(v[i]);
}

TEST(PixelFormats, FourccRoundTripAndNames) {
  EXPECT_EQ(to_fourcc(WireFormat::kYuyv), 0x56595559u);  // 'YUYV' little-endian (videodev2.h)
  EXPECT_EQ(to_fourcc(WireFormat::kZ16), 0x2036315Au);   // V4L2_PIX_FMT_Z16 'Z16 '
  for (auto f : {WireFormat::kYuyv, WireFormat::kUyvy, WireFormat::kRgb8, WireFormat::kBgr8,
                 WireFormat::kMjpeg, WireFormat::kZ16, WireFormat::kY8, WireFormat::kY16}) {
    EXPECT_EQ(wire_format_from_fourcc(to_fourcc(f)), f);
    EXPECT_EQ(wire_format_from_string(to_string(f)), f);
  }
  EXPECT_FALSE(wire_format_from_fourcc(fourcc('N', 'V', '1', '2')).has_value());
  EXPECT_EQ(fourcc_to_string(fourcc('Y', '1', '6', ' ')), "Y16 ");
}

TEST(PixelFormats, YuyvKnownColours) {
  // BT.601 limited range: Y=16 black, Y=235 white, (Y=81,U=90,V=240) is pure red, (41,240,110)
  // pure blue (ITU-R BT.601 colour bar values).
  const auto src = bytes({16, 128, 235, 128, 81, 90, 81, 240, 41, 240, 41, 110});
  std::vector<std::byte> dst(6 * 3);
  ASSERT_EQ(convert_frame({src, 6, 1, 0, WireFormat::kYuyv}, {dst, 0}), ConvertStatus::kOk);
  // black
  EXPECT_EQ(at(dst, 0), 0);
  EXPECT_EQ(at(dst, 1), 0);
  EXPECT_EQ(at(dst, 2), 0);
  // white
  EXPECT_EQ(at(dst, 3), 255);
  EXPECT_EQ(at(dst, 4), 255);
  EXPECT_EQ(at(dst, 5), 255);
  // red: B,G small, R large
  EXPECT_LE(at(dst, 6), 2);
  EXPECT_LE(at(dst, 7), 2);
  EXPECT_GE(at(dst, 8), 253);
  // blue
  EXPECT_GE(at(dst, 12), 253);
  EXPECT_LE(at(dst, 13), 2);
  EXPECT_LE(at(dst, 14), 2);
}

TEST(PixelFormats, UyvyMatchesYuyv) {
  const auto yuyv = bytes({81, 90, 145, 240, 200, 60, 30, 20});
  const auto uyvy = bytes({90, 81, 240, 145, 60, 200, 20, 30});
  std::vector<std::byte> a(4 * 3), b(4 * 3);
  ASSERT_EQ(convert_frame({yuyv, 4, 1, 0, WireFormat::kYuyv}, {a, 0}), ConvertStatus::kOk);
  ASSERT_EQ(convert_frame({uyvy, 4, 1, 0, WireFormat::kUyvy}, {b, 0}), ConvertStatus::kOk);
  EXPECT_EQ(a, b);
}

TEST(PixelFormats, StridesAreHonoured) {
  // 2x2 Y16 with a 6-byte source stride (2 bytes padding) into an 8-byte destination stride.
  const auto src = bytes({1, 0, 2, 0, 0xEE, 0xEE, 3, 0, 4, 1});
  std::vector<std::byte> dst(16, std::byte{0x55});
  ASSERT_EQ(convert_frame({src, 2, 2, 6, WireFormat::kY16}, {dst, 8}), ConvertStatus::kOk);
  std::uint16_t px[2];
  std::memcpy(px, dst.data(), 4);
  EXPECT_EQ(px[0], 1);
  EXPECT_EQ(px[1], 2);
  std::memcpy(px, dst.data() + 8, 4);
  EXPECT_EQ(px[0], 3);
  EXPECT_EQ(px[1], 0x104);
  EXPECT_EQ(at(dst, 4), 0x55);  // destination padding untouched
}

TEST(PixelFormats, TruncatedFrameConvertsRowsPresentAndZeroesTheRest) {
  std::vector<std::byte> src(4 * 2 * 2 + 5, std::byte{7});  // 2 full rows of 4x Z16 + 5 bytes
  std::vector<std::byte> dst(4 * 2 * 3, std::byte{0xFF});
  EXPECT_EQ(convert_frame({src, 4, 3, 0, WireFormat::kZ16}, {dst, 0}), ConvertStatus::kTruncated);
  EXPECT_EQ(at(dst, 0), 7);
  EXPECT_EQ(at(dst, 15), 7);
  EXPECT_EQ(at(dst, 16), 0);
  EXPECT_EQ(at(dst, 23), 0);
}

TEST(PixelFormats, BadGeometryIsAStatus) {
  std::vector<std::byte> src(100), dst(10);
  EXPECT_EQ(convert_frame({src, 5, 1, 0, WireFormat::kYuyv}, {dst, 0}),
            ConvertStatus::kBadGeometry);  // odd width for 4:2:2
  EXPECT_EQ(convert_frame({src, 4, 4, 0, WireFormat::kY8}, {dst, 0}),
            ConvertStatus::kBadGeometry);  // destination too small
  EXPECT_EQ(convert_frame({src, 4, 1, 3, WireFormat::kY16}, {dst, 0}),
            ConvertStatus::kBadGeometry);  // stride shorter than a row
  EXPECT_EQ(convert_frame({src, 0, 1, 0, WireFormat::kY8}, {dst, 0}), ConvertStatus::kBadGeometry);
  EXPECT_EQ(convert_frame({src, 2, 1, 0, WireFormat::kMjpeg}, {dst, 0}),
            ConvertStatus::kUnsupported);
}

TEST(PixelFormats, RgbAndGreyCopyAndDecodedFormats) {
  const auto src = bytes({1, 2, 3, 4, 5, 6});
  std::vector<std::byte> dst(6);
  ASSERT_EQ(convert_frame({src, 2, 1, 0, WireFormat::kRgb8}, {dst, 0}), ConvertStatus::kOk);
  EXPECT_EQ(dst, src);
  EXPECT_EQ(decoded_format(WireFormat::kRgb8), PixelFormat::kRgb8);
  EXPECT_EQ(decoded_format(WireFormat::kYuyv), PixelFormat::kBgr8);
  EXPECT_EQ(decoded_format(WireFormat::kZ16), PixelFormat::kDepth16);
  EXPECT_EQ(decoded_format(WireFormat::kY16), PixelFormat::kMono16);
  EXPECT_EQ(decoded_format(WireFormat::kY8), PixelFormat::kMono8);
}

TEST(Mjpeg, DecodesWhatTurboJpegEncodedAndReportsCorruption) {
  constexpr std::uint32_t w = 64, h = 32;
  std::vector<std::byte> bgr(w * h * 3);
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x) {
      auto* p = reinterpret_cast<std::uint8_t*>(bgr.data()) + (y * w + x) * 3;
      p[0] = static_cast<std::uint8_t>(x * 4);
      p[1] = static_cast<std::uint8_t>(y * 8);
      p[2] = 128;
    }
  }
  std::vector<std::byte> jpeg;
  ASSERT_TRUE(encode_jpeg(bgr, w, h, PixelFormat::kBgr8, 95, jpeg));
  MjpegDecoder dec;
  std::vector<std::byte> out(bgr.size());
  ASSERT_EQ(dec.decode(jpeg, w, h, {out, 0}), ConvertStatus::kOk);
  int max_err = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    max_err = std::max(max_err, std::abs(int(at(out, i)) - int(at(bgr, i))));
  }
  EXPECT_LT(max_err, 16);  // lossy at q95 on a smooth gradient
  EXPECT_EQ(dec.counters().frames, 1u);

  EXPECT_EQ(dec.decode(jpeg, w + 2, h, {out, 0}), ConvertStatus::kBadGeometry);
  EXPECT_EQ(dec.counters().size_mismatch, 1u);

  // Cut inside the entropy-coded data: libjpeg pads with EOI and warns -> a partial frame.
  std::vector<std::byte> cut(jpeg.begin(), jpeg.begin() + static_cast<long>(jpeg.size() * 3 / 4));
  EXPECT_EQ(dec.decode(cut, w, h, {out, 0}), ConvertStatus::kTruncated);
  EXPECT_EQ(dec.counters().partial, 1u);
  // Cut inside the header (tables, SOF): nothing to decode.
  std::vector<std::byte> head(jpeg.begin(), jpeg.begin() + 100);
  EXPECT_EQ(dec.decode(head, w, h, {out, 0}), ConvertStatus::kDecodeError);
  std::vector<std::byte> junk(200, std::byte{0x42});
  EXPECT_EQ(dec.decode(junk, w, h, {out, 0}), ConvertStatus::kDecodeError);
  EXPECT_EQ(dec.counters().errors, 2u);
  // And the decoder still works after errors.
  EXPECT_EQ(dec.decode(jpeg, w, h, {out, 0}), ConvertStatus::kOk);

  std::vector<std::byte> grey(w * h);
  ASSERT_EQ(dec.decode(jpeg, w, h, {grey, 0}, PixelFormat::kMono8), ConvertStatus::kOk);
}

}  // namespace
}  // namespace posed::drivers::camera

namespace posed::drivers::camera {
namespace {

// The table-driven kernel against the BT.601 fixed-point formula it tabulates (OpenCV's
// ITUR_BT_601 coefficients, 20-bit), for every Y, U and V.
TEST(PixelFormats, YuyvKernelMatchesTheFixedPointFormulaForAllSamples) {
  constexpr int kShift = 20, kCY = 1220542, kCVR = 1673527, kCVG = -852492, kCUG = -409993,
                kCUB = 2116026, kRound = 1 << 19;
  auto clamp = [](int x) { return x < 0 ? 0 : x > 255 ? 255 : x; };
  std::vector<std::uint8_t> row(512), out(768);
  int mismatches = 0;
  for (int u = 0; u < 256; ++u) {
    for (int v = 0; v < 256; ++v) {
      for (int k = 0; k < 128; ++k) {  // pairs (Y0, Y1) = (2k, 2k + 1): every Y once
        row[4 * k] = static_cast<std::uint8_t>(2 * k);
        row[4 * k + 1] = static_cast<std::uint8_t>(u);
        row[4 * k + 2] = static_cast<std::uint8_t>(2 * k + 1);
        row[4 * k + 3] = static_cast<std::uint8_t>(v);
      }
      yuv422_to_bgr(row.data(), 512, out.data(), 768, 256, 1, false);
      for (int y = 0; y < 256; ++y) {
        const int yy = std::max(0, y - 16) * kCY;
        const int b = clamp((yy + kRound + kCUB * (u - 128)) >> kShift);
        const int g = clamp((yy + kRound + kCVG * (v - 128) + kCUG * (u - 128)) >> kShift);
        const int r = clamp((yy + kRound + kCVR * (v - 128)) >> kShift);
        mismatches += out[3 * y] != b || out[3 * y + 1] != g || out[3 * y + 2] != r;
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
}

}  // namespace
}  // namespace posed::drivers::camera
