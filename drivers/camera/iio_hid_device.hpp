#pragma once
// Sets up one Linux IIO HID sensor (hid-sensor-accel-3d, hid-sensor-gyro-3d) for buffered
// capture through sysfs, the way librealsense's Linux backend does (src/linux/backend-hid.cpp,
// iio_hid_sensor::init / start_capture / stop_capture): find /sys/bus/iio/devices/iio:deviceN
// by its `name`, enable every scan element (scan_elements/in_*_en = 1) and read its _type and
// _index, write the rate to the attribute whose name contains "sampling_frequency", write
// buffer/length, drop records left in the kernel FIFO, then buffer/enable = 1; records are read
// from /dev/iio:deviceN. The sysfs root and /dev are injectable so tests run on a fake tree.

#include <cstdint>
#include <string>

#include "drivers/camera/iio_scan.hpp"

namespace posed::drivers::camera {

struct IioHidDeviceConfig {
  /// where the IIO devices are listed
  std::string sysfs_root = "/sys/bus/iio/devices";
  /// where their character devices are (iio:deviceN)
  std::string dev_dir = "/dev";
  /// the device's `name` attribute: "accel_3d" or "gyro_3d" for the D435i
  std::string name;
  /// "iio:deviceN" to pin one device; empty = the first (in name order) whose name matches
  std::string device_dir;
  /// written to the *sampling_frequency attribute [Hz]; 0 keeps the device's
  double sampling_frequency_hz = 0.0;
  /// buffer/length: records the kernel keeps between reads (librealsense: hid_buf_len, 128)
  std::uint32_t buffer_length = 128;
};

struct IioHidDevice {
  std::string sysfs_dir;  ///< e.g. /sys/bus/iio/devices/iio:device3
  std::string dev_node;   ///< e.g. /dev/iio:device3
  IioScanLayout layout;   ///< the enabled scan elements
};

/// Finds the device, configures and enables its buffer. false with `error` naming the path and
/// the attribute that failed.
bool enable_iio_hid_device(const IioHidDeviceConfig& config, IioHidDevice& out, std::string& error);
/// buffer/enable = 0 (best effort: the device may be gone).
void disable_iio_hid_device(const IioHidDevice& device);

}  // namespace posed::drivers::camera
