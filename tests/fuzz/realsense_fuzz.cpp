// libFuzzer target: the bytes a RealSense D4xx hands over besides pixels. Every input goes
// through each parser:
//  - the UVC metadata of a frame (parse_d4xx_metadata);
//  - an HW monitor reply and command (parse_hwm_reply, parse_hwm_command);
//  - a GETINTCAL calibration table 25 and 32, as sent and with its table id and CRC-32 made
//    right, so the fuzzer reaches the table body instead of stopping at the checksum;
//  - IIO HID records: the text up to the first '\n' is the channel's wire format (scan layout,
//    from a recording's metadata), the bytes after it the records (RealsenseImuDecoder).
// Contracts beyond "no crash, no UB": a refusal says why, parsed values are finite, a wire format
// that parses reads back the same, every record byte is decoded or counted as partial.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/camera/d4xx_calibration.hpp"
#include "drivers/camera/d4xx_hw_monitor.hpp"
#include "drivers/camera/d4xx_metadata.hpp"
#include "drivers/camera/iio_scan.hpp"
#include "drivers/camera/realsense_imu_decoder.hpp"
#include "drivers/common/wire_format.hpp"
#include "drivers/recording/crc32.hpp"

namespace cam = posed::drivers::camera;
namespace wire = posed::drivers::wire;

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

void metadata(std::span<const std::byte> b) {
  cam::D4xxFrameMetadata m;
  const cam::MetadataStatus s = cam::parse_d4xx_metadata(b, m);
  check(!cam::to_string(s).empty());
  // A block claims a size the header has room for: what was read lies inside the input.
  if (m.has_pts) check(b.size() >= cam::kUvcMetaBufPrefixBytes + 6);
}

void hw_monitor(std::span<const std::byte> b) {
  std::span<const std::byte> payload;
  std::int32_t echoed = 0;
  if (cam::parse_hwm_reply(b, cam::kHwmOpGetIntCal, payload, echoed) == cam::HwmStatus::kOk) {
    check(payload.size() + 4 == b.size());
  }
  cam::HwmCommand c;
  if (cam::parse_hwm_command(b, c)) check(c.data.size() <= b.size());
}

/// The table with bytes 2..3 naming `id` and bytes 12..15 holding the CRC of the rest.
std::vector<std::byte> with_valid_header(std::span<const std::byte> b, cam::D4xxTableId id) {
  std::vector<std::byte> t(b.begin(), b.end());
  if (t.size() < cam::kD4xxTableHeaderBytes) return t;
  const auto n = static_cast<std::uint16_t>(id);
  t[2] = static_cast<std::byte>(n & 0xFF);
  t[3] = static_cast<std::byte>(n >> 8);
  const std::uint32_t crc =
      posed::drivers::recording::crc32(std::span<const std::byte>(t).subspan(16));
  for (int i = 0; i < 4; ++i)
    t[12 + static_cast<std::size_t>(i)] = static_cast<std::byte>(crc >> (8 * i));
  return t;
}

void calibration(std::span<const std::byte> b) {
  // Stream sizes as configs give them: exact table entries, one scaled, one odd.
  constexpr std::uint32_t kSizes[][2] = {{640, 480}, {1280, 720}, {1024, 768}, {1, 1}};
  cam::D4xxTableHeader h;
  std::string error;
  if (!cam::check_d4xx_table(b, cam::D4xxTableId::kCoefficients, h, error)) check(!error.empty());
  const auto t25 = with_valid_header(b, cam::D4xxTableId::kCoefficients);
  const auto t32 = with_valid_header(b, cam::D4xxTableId::kRgbCalibration);
  for (const auto& [w, hgt] : kSizes) {
    cam::D4xxDepthCalibration depth;
    error.clear();
    if (cam::parse_d4xx_coefficients_table(t25, w, hgt, depth, error)) {
      check(std::isfinite(depth.depth.fx) && depth.depth.fx > 0 && std::isfinite(depth.baseline_m));
    } else {
      check(!error.empty());
    }
    cam::D4xxColourCalibration colour;
    error.clear();
    if (cam::parse_d4xx_rgb_table(t32, w, hgt, colour, error)) {
      check(colour.T_depth_colour.allFinite() && colour.T_colour_depth.allFinite());
    } else {
      check(!error.empty());
    }
  }
}

void iio(std::span<const std::byte> b) {
  const std::string_view all(reinterpret_cast<const char*>(b.data()), b.size());
  const std::size_t nl = all.find('\n');
  if (nl == std::string_view::npos) return;
  const std::string_view layout_text = all.substr(0, nl);
  const auto records = b.subspan(nl + 1);
  cam::RealsenseImuDecoder decoder(layout_text);
  std::vector<cam::D4xxMotionSample> out(64);
  const std::size_t n = decoder.decode(records, out);
  if (!decoder.valid()) {
    check(!decoder.error().empty() && n == 0);
    return;
  }
  check(decoder.record_bytes() > 0);
  check(n == std::min<std::size_t>(out.size(), records.size() / decoder.record_bytes()));
  check(decoder.counters().partial_bytes == records.size() % decoder.record_bytes());
  for (std::size_t i = 0; i < n; ++i) check(out[i].xyz_depth.allFinite());
  // The layout as a recording writes it back reads the same.
  const std::string_view prefix =
      decoder.kind() == cam::MotionKind::kAccel ? wire::kIioAccel3d : wire::kIioGyro3d;
  cam::IioScanLayout layout, again;
  std::string error;
  check(cam::parse_iio_layout(layout_text, prefix, layout, error));
  check(cam::parse_iio_layout(cam::describe_iio_layout(prefix, layout), prefix, again, error));
  check(again.record_bytes == layout.record_bytes &&
        again.elements.size() == layout.elements.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto b = std::span(reinterpret_cast<const std::byte*>(data), size);
  metadata(b);
  hw_monitor(b);
  calibration(b);
  iio(b);
  return 0;
}
