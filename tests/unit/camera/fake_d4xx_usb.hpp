#pragma once
// A D435i HW-monitor endpoint for tests: decodes each command packet as the firmware would and
// answers GETINTCAL with calibration tables laid out as librealsense's d400_coefficients_table /
// d400_rgb_calibration_table, built field by field from known values, with the header CRC-32.
// Faults (bad CRC, short reply, wrong opcode, no device) are switches.

#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "drivers/camera/d4xx_calibration.hpp"
#include "drivers/camera/d4xx_hw_monitor.hpp"
#include "drivers/camera/usb_transport.hpp"
#include "drivers/recording/crc32.hpp"

namespace posed::test {

/// Known calibration the fake serves.
struct KnownD435iCalibration {
  // depth rect_params for 640x480 (index res_640_480) and 1920x1080 (index 0)
  float depth_640_fx = 383.5f, depth_640_fy = 383.25f, depth_640_cx = 320.75f,
        depth_640_cy = 237.5f;
  float depth_1080_fx = 1150.5f, depth_1080_fy = 1150.0f, depth_1080_cx = 962.0f,
        depth_1080_cy = 712.5f;
  float baseline_mm = -50.0125f;  // stored signed by the firmware
  // colour calibrated at 1920x1080
  float colour_fx = 1380.0f, colour_fy = 1378.0f, colour_cx = 972.0f, colour_cy = 534.0f;
  float distortion[5] = {0.125f, -0.25f, 0.001f, -0.002f, 0.0625f};
  float yaw_rad = 0.01f;                                 // rotation about y
  float translation_rect_mm[3] = {-15.0f, 0.25f, 0.5f};  // as stored
};

struct TableBytes {
  std::vector<std::byte> v;
  void u8(std::uint32_t x) { v.push_back(static_cast<std::byte>(x & 0xFF)); }
  void u16(std::uint32_t x) { u8(x), u8(x >> 8); }
  void u32(std::uint32_t x) { u16(x & 0xFFFF), u16(x >> 16); }
  void f32(float f) { u32(std::bit_cast<std::uint32_t>(f)); }
  void zeros(std::size_t n) { v.insert(v.end(), n, std::byte{0}); }
  /// column-major float3x3 from a row-major list
  void mat3_row_major(const float (&m)[9]) {
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) f32(m[3 * i + j]);
  }
  /// fills table_header: version 0x0203 big-endian, id, size of the payload, CRC-32 of it
  void finish_header(std::uint16_t id) {
    const std::size_t payload = v.size() - 16;
    v[0] = std::byte{0x02};
    v[1] = std::byte{0x03};
    v[2] = static_cast<std::byte>(id & 0xFF);
    v[3] = static_cast<std::byte>(id >> 8);
    for (int i = 0; i < 4; ++i) v[4 + i] = static_cast<std::byte>((payload >> (8 * i)) & 0xFF);
    const std::uint32_t crc = drivers::recording::crc32(std::span<const std::byte>(v).subspan(16));
    for (int i = 0; i < 4; ++i) v[12 + i] = static_cast<std::byte>((crc >> (8 * i)) & 0xFF);
  }
};

inline std::vector<std::byte> coefficients_table(const KnownD435iCalibration& k) {
  TableBytes t;
  t.zeros(16);
  const float eye[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (int m = 0; m < 4; ++m) t.mat3_row_major(eye);  // intrinsic_left/right, world2left/right
  t.f32(k.baseline_mm);
  t.u32(1);  // brown_model
  t.zeros(88);
  for (int r = 0; r < 16; ++r) {  // rect_params[ds_rect_resolutions]
    if (r == 0) {
      for (float f : {k.depth_1080_fx, k.depth_1080_fy, k.depth_1080_cx, k.depth_1080_cy}) t.f32(f);
    } else if (r == 2) {
      for (float f : {k.depth_640_fx, k.depth_640_fy, k.depth_640_cx, k.depth_640_cy}) t.f32(f);
    } else {
      for (int i = 0; i < 4; ++i) t.f32(0.0f);  // unfilled: librealsense's "DS5U" ideal case
    }
  }
  t.zeros(64);
  t.finish_header(25);
  return t.v;
}

inline std::vector<std::byte> rgb_table(const KnownD435iCalibration& k) {
  TableBytes t;
  t.zeros(16);
  // intrinsic normalised to [-1, 1] at the calibrated 1920x1080:
  // [[fx', 0, 0], [0, fy', 0], [cx', cy', 1]] in librealsense's (row, column) indexing, i.e.
  // (2,0) = 2cx/W - 1, (2,1) = 2cy/H - 1.
  const float n[9] = {
      2 * k.colour_fx / 1920,     0, 0, 0, 2 * k.colour_fy / 1080, 0, 2 * k.colour_cx / 1920 - 1,
      2 * k.colour_cy / 1080 - 1, 1};
  t.mat3_row_major(n);
  for (float d : k.distortion) t.f32(d);
  for (int i = 0; i < 3; ++i) t.f32(0);   // rotation (Rodrigues), unused by the parser
  for (int i = 0; i < 3; ++i) t.f32(0);   // translation
  for (int i = 0; i < 12; ++i) t.f32(0);  // projection
  t.u16(1920);
  t.u16(1080);
  for (int i = 0; i < 9; ++i) t.f32(0);  // intrinsic_matrix_rect
  const float c = std::cos(k.yaw_rad), s = std::sin(k.yaw_rad);
  const float r[9] = {c, 0, s, 0, 1, 0, -s, 0, c};
  t.mat3_row_major(r);
  for (float f : k.translation_rect_mm) t.f32(f);
  t.zeros(24);
  t.finish_header(32);
  return t.v;
}

class FakeD4xxUsb final : public drivers::camera::UsbTransport {
 public:
  KnownD435iCalibration known;
  bool present = true;
  bool corrupt_crc = false;        ///< flip a payload byte after the CRC was computed
  std::size_t cut_reply_to = 0;    ///< >0: send only this many bytes
  std::int32_t answer_opcode = 0;  ///< !=0: echo this instead of the command's opcode
  int transactions = 0;
  std::vector<drivers::camera::HwmCommand> seen;
  std::vector<std::vector<std::byte>> seen_packets;

  bool open(std::string& error) override {
    if (!present) {
      error = "usb 8086:0b3a: no such USB device connected";
      return false;
    }
    return true;
  }
  std::string describe() const override { return "fake usb 8086:0b3a"; }
  std::ptrdiff_t transact(std::span<const std::byte> command, std::span<std::byte> reply, int,
                          std::string& error) override {
    ++transactions;
    seen_packets.emplace_back(command.begin(), command.end());
    drivers::camera::HwmCommand cmd;
    if (!drivers::camera::parse_hwm_command(seen_packets.back(), cmd)) {
      error = "fake: malformed command packet";
      return -1;
    }
    seen.push_back(cmd);
    std::vector<std::byte> out;
    const std::uint32_t echo =
        answer_opcode != 0 ? static_cast<std::uint32_t>(answer_opcode) : cmd.opcode;
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::byte>((echo >> (8 * i)) & 0xFF));
    if (cmd.opcode == drivers::camera::kHwmOpGetIntCal) {
      std::vector<std::byte> table;
      if (cmd.params[0] == 25) table = coefficients_table(known);
      if (cmd.params[0] == 32) table = rgb_table(known);
      if (corrupt_crc && !table.empty()) table[100] ^= std::byte{0x01};
      out.insert(out.end(), table.begin(), table.end());
    }
    if (cut_reply_to > 0 && cut_reply_to < out.size()) out.resize(cut_reply_to);
    const std::size_t n = std::min(out.size(), reply.size());
    std::memcpy(reply.data(), out.data(), n);
    return static_cast<std::ptrdiff_t>(n);
  }
};

}  // namespace posed::test
