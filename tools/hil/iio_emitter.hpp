#pragma once
// Plays the D435i's IMU back the way Linux exposes it, for a live posed on a machine without the
// camera: under DIR it makes what the kernel's HID sensor drivers make, a sysfs device per
// sensor (DIR/sys/iio:device0 "accel_3d", iio:device1 "gyro_3d": name, buffer/enable and
// length, the rate attribute, and scan_elements/*_en, _type, _index in the recorded layout)
// and its character device (DIR/dev/iio:deviceN, a FIFO), and writes the recorded records to
// it. posed reads them as from the camera with realsense_imu.sysfs_root: DIR/sys and
// realsense_imu.dev_dir: DIR/dev.
//
// Like the kernel's buffer, the FIFO keeps what a slow or absent reader has not read, up to its
// size; records beyond that are dropped whole (never half a record: the reader would lose the
// record boundaries) and counted.

#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace posed::hil {

struct IioCounters {
  std::uint64_t writes = 0;         ///< chunks written (all or part of their records)
  std::uint64_t bytes = 0;          ///< bytes written [B]
  std::uint64_t bytes_dropped = 0;  ///< whole records the FIFO had no room for [B]
};

class IioEmitter {
 public:
  explicit IioEmitter(std::string dir) : dir_(std::move(dir)) {}
  /// Closes the FIFOs; the tree stays (a reader may still hold it), and the next add() of the
  /// same device replaces it.
  ~IioEmitter();
  IioEmitter(const IioEmitter&) = delete;
  IioEmitter& operator=(const IioEmitter&) = delete;

  /// Makes the device of a recorded channel's wire format ("iio-hid-accel-3d;in_accel_x:..." or
  /// the gyro's) and opens its FIFO. false + `error` ("iio DIR: reason").
  bool add(std::string_view wire_format, std::string& error);
  /// Writes a chunk of whole records of that wire format's device; false when some or all were
  /// dropped (counted).
  bool write(std::string_view wire_format, std::span<const std::byte> bytes);

  /// from any thread
  IioCounters counters() const;
  const std::string& dir() const { return dir_; }

 private:
  struct Device {
    std::string wire_format;
    int fd = -1;
    std::uint32_t record_bytes = 0;
  };
  std::string dir_;
  std::array<Device, 2> devices_;  // accel, gyro
  std::atomic<std::uint64_t> writes_{0}, bytes_{0}, bytes_dropped_{0};
};

}  // namespace posed::hil
