#pragma once
// Reads the D435i's factory calibration over the HW monitor (GETINTCAL for tables 25 and 32,
// as librealsense's d400_device::get_d400_raw_calibration_table does) and parses it. When the
// device cannot be reached or its answer is unusable, the caller's fallback (the configured
// intrinsics/extrinsics) is returned and ONE log line says why.

#include <string>
#include <vector>

#include "drivers/camera/d4xx_calibration.hpp"
#include "drivers/camera/usb_transport.hpp"

namespace posed::drivers::camera {

struct D4xxCalibration {
  D4xxDepthCalibration depth;
  D4xxColourCalibration colour;
  /// true when read from the camera, false when this is the fallback
  bool from_device = false;
  /// where it came from, for logs and status ("usb 8086:0b3a (...)" or "config")
  std::string source;
};

/// Stream sizes the intrinsics are wanted for [px].
struct D4xxStreamSizes {
  std::uint32_t depth_width = 640, depth_height = 480;
  std::uint32_t colour_width = 640, colour_height = 480;
};

/// One GETINTCAL round trip: the table's bytes (header included). false with `error` naming
/// the device, the table id and what was wrong (transfer, short reply, wrong opcode).
bool read_d4xx_table(UsbTransport& usb, D4xxTableId id, std::vector<std::byte>& table,
                     std::string& error, int timeout_ms = 1000);

/// Both tables parsed for `sizes`; false with `error` (no log line).
bool read_d4xx_calibration(UsbTransport& usb, const D4xxStreamSizes& sizes, D4xxCalibration& out,
                           std::string& error, int timeout_ms = 1000);

/// read_d4xx_calibration(), or `fallback` (source "config") with one warning naming the reason.
D4xxCalibration d4xx_calibration_or_fallback(UsbTransport& usb, const D4xxStreamSizes& sizes,
                                             const D4xxCalibration& fallback,
                                             int timeout_ms = 1000);

}  // namespace posed::drivers::camera
