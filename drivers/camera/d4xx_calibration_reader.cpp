#include "drivers/camera/d4xx_calibration_reader.hpp"

#include "drivers/camera/d4xx_hw_monitor.hpp"
#include "drivers/common/log.hpp"

namespace posed::drivers::camera {

bool read_d4xx_table(UsbTransport& usb, D4xxTableId id, std::vector<std::byte>& table,
                     std::string& error, int timeout_ms) {
  const auto command = build_hwm_command(kHwmOpGetIntCal, static_cast<std::uint32_t>(id));
  std::vector<std::byte> reply(kHwmMaxReplyBytes);
  const std::string what =
      usb.describe() + ": GETINTCAL table " + std::to_string(static_cast<int>(id));
  std::string transfer_error;
  const std::ptrdiff_t n = usb.transact(command, reply, timeout_ms, transfer_error);
  if (n < 0) {
    error = what + ": " + transfer_error;
    return false;
  }
  std::span<const std::byte> payload;
  std::int32_t echoed = 0;
  switch (parse_hwm_reply(std::span(reply).first(static_cast<std::size_t>(n)), kHwmOpGetIntCal,
                          payload, echoed)) {
    case HwmStatus::kOk:
      break;
    case HwmStatus::kTooShort:
      error = what + ": reply of " + std::to_string(n) + " bytes has no opcode echo";
      return false;
    case HwmStatus::kWrongOpcode:
      error = what + ": reply echoes opcode " + std::to_string(echoed) +
              (echoed < 0 ? " (a firmware error code)" : "") + ", expected " +
              std::to_string(kHwmOpGetIntCal);
      return false;
  }
  table.assign(payload.begin(), payload.end());
  return true;
}

bool read_d4xx_calibration(UsbTransport& usb, const D4xxStreamSizes& sizes, D4xxCalibration& out,
                           std::string& error, int timeout_ms) {
  if (!usb.open(error)) return false;
  std::vector<std::byte> coefficients, rgb;
  if (!read_d4xx_table(usb, D4xxTableId::kCoefficients, coefficients, error, timeout_ms) ||
      !read_d4xx_table(usb, D4xxTableId::kRgbCalibration, rgb, error, timeout_ms)) {
    return false;
  }
  D4xxCalibration c;
  std::string parse_error;
  if (!parse_d4xx_coefficients_table(coefficients, sizes.depth_width, sizes.depth_height, c.depth,
                                     parse_error) ||
      !parse_d4xx_rgb_table(rgb, sizes.colour_width, sizes.colour_height, c.colour, parse_error)) {
    error = usb.describe() + ": " + parse_error;
    return false;
  }
  c.from_device = true;
  c.source = usb.describe();
  out = std::move(c);
  return true;
}

D4xxCalibration d4xx_calibration_or_fallback(UsbTransport& usb, const D4xxStreamSizes& sizes,
                                             const D4xxCalibration& fallback, int timeout_ms) {
  D4xxCalibration c;
  std::string error;
  if (read_d4xx_calibration(usb, sizes, c, error, timeout_ms)) {
    POSED_LOG_INFO("camera calibration read from %s", c.source.c_str());
    return c;
  }
  POSED_LOG_WARN(
      "camera factory calibration unavailable, using the configured intrinsics and "
      "extrinsics: %s",
      error.c_str());
  c = fallback;
  c.from_device = false;
  c.source = "config";
  return c;
}

}  // namespace posed::drivers::camera
