// D4xx HW monitor and factory calibration: command packets byte for byte, replies checked,
// calibration tables (built field by field from known values by the fake) parsed back, and
// the fallback to the configured calibration.
#include "drivers/camera/d4xx_calibration.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "drivers/camera/d4xx_calibration_reader.hpp"
#include "drivers/camera/d4xx_hw_monitor.hpp"
#include "tests/unit/camera/fake_d4xx_usb.hpp"

namespace posed::drivers::camera {
namespace {

std::vector<std::byte> bytes(std::initializer_list<int> v) {
  std::vector<std::byte> out;
  for (int x : v) out.push_back(static_cast<std::byte>(x));
  return out;
}

TEST(HwMonitor, GetIntCalCommandIsTheFirmwarePacket) {
  // length 20 (0x14) = everything after length and magic; magic 0xCDAB little-endian; opcode
  // 0x15; param1 = table 25; params 2..4 zero.
  const auto p = build_hwm_command(kHwmOpGetIntCal, 25);
  EXPECT_EQ(p, bytes({0x14, 0x00, 0xAB, 0xCD, 0x15, 0, 0, 0, 25, 0, 0, 0,
                      0,    0,    0,    0,    0,    0, 0, 0, 0,  0, 0, 0}));
  const auto d = bytes({1, 2, 3});
  const auto with_data = build_hwm_command(0x2B, 1, 2, 3, 4, d);
  ASSERT_EQ(with_data.size(), 27u);
  EXPECT_EQ(with_data[0], std::byte{23});
  HwmCommand c;
  ASSERT_TRUE(parse_hwm_command(with_data, c));
  EXPECT_EQ(c.opcode, 0x2Bu);
  EXPECT_EQ(c.params[3], 4u);
  EXPECT_EQ(c.data.size(), 3u);
  auto bad_magic = with_data;
  bad_magic[2] = std::byte{0};
  EXPECT_FALSE(parse_hwm_command(bad_magic, c));
  EXPECT_FALSE(parse_hwm_command(std::span(with_data).first(26), c));  // length disagrees
}

TEST(HwMonitor, RepliesAreCheckedForTheOpcodeEcho) {
  std::span<const std::byte> payload;
  std::int32_t echoed = 0;
  const auto ok = bytes({0x15, 0, 0, 0, 9, 8});
  EXPECT_EQ(parse_hwm_reply(ok, 0x15, payload, echoed), HwmStatus::kOk);
  EXPECT_EQ(payload.size(), 2u);
  EXPECT_EQ(parse_hwm_reply(bytes({0x15, 0, 0}), 0x15, payload, echoed), HwmStatus::kTooShort);
  // hwm_WrongCommand-style negative code in place of the echo
  EXPECT_EQ(parse_hwm_reply(bytes({0xFE, 0xFF, 0xFF, 0xFF}), 0x15, payload, echoed),
            HwmStatus::kWrongOpcode);
  EXPECT_EQ(echoed, -2);
  EXPECT_TRUE(payload.empty());
}

TEST(D4xxCalibration, TablesFromTheDeviceParseBackToTheKnownValues) {
  test::FakeD4xxUsb usb;
  D4xxCalibration c;
  std::string error;
  ASSERT_TRUE(read_d4xx_calibration(usb, {640, 480, 640, 480}, c, error)) << error;
  ASSERT_EQ(usb.seen.size(), 2u);
  EXPECT_EQ(usb.seen[0].opcode, kHwmOpGetIntCal);
  EXPECT_EQ(usb.seen[0].params[0], 25u);
  EXPECT_EQ(usb.seen[1].params[0], 32u);
  EXPECT_TRUE(c.from_device);
  EXPECT_EQ(c.source, "fake usb 8086:0b3a");
  const auto& k = usb.known;
  EXPECT_FLOAT_EQ(static_cast<float>(c.depth.depth.fx), k.depth_640_fx);
  EXPECT_FLOAT_EQ(static_cast<float>(c.depth.depth.fy), k.depth_640_fy);
  EXPECT_FLOAT_EQ(static_cast<float>(c.depth.depth.cx), k.depth_640_cx);
  EXPECT_FLOAT_EQ(static_cast<float>(c.depth.depth.cy), k.depth_640_cy);
  EXPECT_EQ(c.depth.depth.distortion, (std::array<double, 5>{}));
  EXPECT_NEAR(c.depth.baseline_m, 0.0500125, 1e-9);

  // Colour at 640x480: the 4:3 mode is the 16:9 calibration scaled by 480/1080 and cropped.
  const double s = 480.0 / 1080.0;
  EXPECT_NEAR(c.colour.colour.fx, k.colour_fx * s, 1e-3);
  EXPECT_NEAR(c.colour.colour.fy, k.colour_fy * s, 1e-3);
  EXPECT_NEAR(c.colour.colour.cx, 320 + (k.colour_cx - 960) * s, 1e-3);
  EXPECT_NEAR(c.colour.colour.cy, 240 + (k.colour_cy - 540) * s, 1e-3);
  EXPECT_FLOAT_EQ(static_cast<float>(c.colour.colour.distortion[4]), 0.0625f);
  // Extrinsics: rotation as stored, translation mm -> m with librealsense's -0.001.
  const Eigen::Matrix4d& T = c.colour.T_depth_colour;
  EXPECT_NEAR(T(0, 0), std::cos(0.01), 1e-7);
  EXPECT_NEAR(T(0, 2), std::sin(0.01), 1e-7);
  EXPECT_NEAR(T(2, 0), -std::sin(0.01), 1e-7);
  EXPECT_NEAR(T(0, 3), 0.015, 1e-9);
  EXPECT_NEAR(T(1, 3), -0.00025, 1e-9);
  EXPECT_NEAR(T(2, 3), -0.0005, 1e-9);
  EXPECT_TRUE((c.colour.T_colour_depth * T).isIdentity(1e-6));
}

TEST(D4xxCalibration, SizesWithoutTheirOwnEntryScaleTheFullHdOne) {
  test::FakeD4xxUsb usb;
  D4xxCalibration c;
  std::string error;
  // 384x216 (a fifth of 1920x1080) is not among ds_rect_resolutions.
  ASSERT_TRUE(read_d4xx_calibration(usb, {384, 216, 1920, 1080}, c, error)) << error;
  EXPECT_NEAR(c.depth.depth.fx, usb.known.depth_1080_fx / 5, 1e-3);
  EXPECT_NEAR(c.depth.depth.cy, usb.known.depth_1080_cy / 5, 1e-3);
  // 1280x720 has an entry, but left unfilled (fx == fy, cx == cy): ideal optics.
  ASSERT_TRUE(read_d4xx_calibration(usb, {1280, 720, 1920, 1080}, c, error)) << error;
  EXPECT_DOUBLE_EQ(c.depth.depth.fx, 1280 * 1.5);
  EXPECT_DOUBLE_EQ(c.depth.depth.cy, 360);
  // Colour at its calibrated size: the normalised values exactly.
  EXPECT_NEAR(c.colour.colour.fx, usb.known.colour_fx, 1e-3);
  EXPECT_NEAR(c.colour.colour.cx, usb.known.colour_cx, 1e-3);
}

TEST(D4xxCalibration, BadCrcShortReplyAndWrongOpcodeAreRejectedWithContext) {
  D4xxCalibration c;
  std::string error;
  test::FakeD4xxUsb crc;
  crc.corrupt_crc = true;
  EXPECT_FALSE(read_d4xx_calibration(crc, {}, c, error));
  EXPECT_NE(error.find("calibration table 25: CRC-32"), std::string::npos) << error;

  test::FakeD4xxUsb cut;
  cut.cut_reply_to = 4 + 300;
  EXPECT_FALSE(read_d4xx_calibration(cut, {}, c, error));
  EXPECT_NE(error.find("calibration table 25: 300 bytes, the table needs 576"), std::string::npos)
      << error;
  cut.cut_reply_to = 3;
  EXPECT_FALSE(read_d4xx_calibration(cut, {}, c, error));
  EXPECT_NE(error.find("GETINTCAL table 25: reply of 3 bytes"), std::string::npos) << error;

  test::FakeD4xxUsb wrong;
  wrong.answer_opcode = -7;
  EXPECT_FALSE(read_d4xx_calibration(wrong, {}, c, error));
  EXPECT_NE(error.find("echoes opcode -7 (a firmware error code), expected 21"), std::string::npos)
      << error;

  // A table of the other kind where 25 was asked for.
  const auto rgb = test::rgb_table(crc.known);
  D4xxDepthCalibration depth;
  EXPECT_FALSE(parse_d4xx_coefficients_table(rgb, 640, 480, depth, error));
  // (the RGB table is shorter than a coefficients table)
  EXPECT_NE(error.find("calibration table 25"), std::string::npos) << error;
  D4xxTableHeader h;
  EXPECT_FALSE(check_d4xx_table(rgb, D4xxTableId::kCoefficients, h, error));
  EXPECT_NE(error.find("header at offset 2 names table 32"), std::string::npos) << error;
  EXPECT_TRUE(check_d4xx_table(rgb, D4xxTableId::kRgbCalibration, h, error)) << error;
  EXPECT_EQ(h.version, 0x0203);
  EXPECT_EQ(h.table_size, kD4xxRgbTableBytes - 16);
}

TEST(D4xxCalibration, UnreachableDeviceFallsBackToTheConfiguredCalibration) {
  test::FakeD4xxUsb usb;
  usb.present = false;
  D4xxCalibration fallback;
  fallback.colour.colour.fx = 617.971;
  fallback.depth.baseline_m = 0.05;
  const D4xxCalibration c = d4xx_calibration_or_fallback(usb, {}, fallback);
  EXPECT_FALSE(c.from_device);
  EXPECT_EQ(c.source, "config");
  EXPECT_DOUBLE_EQ(c.colour.colour.fx, 617.971);
  EXPECT_EQ(usb.transactions, 0);

  test::FakeD4xxUsb ok;
  const D4xxCalibration d = d4xx_calibration_or_fallback(ok, {}, fallback);
  EXPECT_TRUE(d.from_device);
  EXPECT_NEAR(d.depth.baseline_m, 0.0500125, 1e-9);
}

}  // namespace
}  // namespace posed::drivers::camera
