#pragma once
// The D435i IMU as a Source: its accelerometer and gyro are two Linux IIO HID devices
// (hid-sensor-accel-3d "accel_3d", hid-sensor-gyro-3d "gyro_3d"), read the way librealsense's
// Linux backend reads them (src/linux/backend-hid.cpp; setup in iio_hid_device.hpp). Each read()
// returns whole scan records exactly as /dev/iio:deviceN gave them: channel 0 accel, channel 1
// gyro. The wire format of each channel carries its record layout ("iio-hid-accel-3d;in_accel_x:
// le:s16/32>>0;..."), so RealsenseImuDecoder decodes live and recorded bytes alike. A read that
// ends inside a record keeps the tail for the next read (a record is never split across
// chunks). When a device disappears (USB unplug) read() reports kDeviceLost and later calls
// reopen both devices, rediscovering them by name.

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "drivers/camera/iio_hid_device.hpp"
#include "drivers/common/source.hpp"

namespace posed::drivers::camera {

/// An IioHidDeviceConfig for the device called `name` at `rate_hz`, other fields default.
inline IioHidDeviceConfig iio_hid_config(std::string name, double rate_hz) {
  IioHidDeviceConfig c;
  c.name = std::move(name);
  c.sampling_frequency_hz = rate_hz;
  return c;
}

struct RealsenseImuSourceConfig {
  /// name "accel_3d"; rate 63 or 250 Hz (100 or 200 on newer firmware)
  IioHidDeviceConfig accel = iio_hid_config("accel_3d", 250.0);
  /// name "gyro_3d"; rate 200 or 400 Hz
  IioHidDeviceConfig gyro = iio_hid_config("gyro_3d", 200.0);
  /// wait between reopen attempts while the devices are gone [ms]
  int reopen_interval_ms = 500;
};

struct RealsenseImuSourceCounters {
  std::uint64_t accel_records = 0;  ///< whole accel records delivered
  std::uint64_t gyro_records = 0;   ///< whole gyro records delivered
  std::uint64_t lost = 0;           ///< times the devices disappeared
};

class RealsenseImuSource final : public Source {
 public:
  RealsenseImuSource(std::string name, RealsenseImuSourceConfig config);
  ~RealsenseImuSource() override;
  std::string_view name() const override { return name_; }
  /// valid after open(); empty before
  std::string_view wire_format(std::uint32_t channel) const override;
  bool open(std::string& error) override;
  ReadStatus read(RawChunk& chunk, Duration timeout) override;
  void request_stop() override { stop_.store(true, std::memory_order_relaxed); }
  SourceCounters counters() const override;
  const RealsenseImuSourceCounters& imu_counters() const { return imu_counters_; }
  const IioHidDevice& device(std::uint32_t channel) const { return channels_[channel].device; }

 private:
  struct Channel {
    IioHidDevice device;
    int fd = -1;
    std::string wire_format;
    std::vector<std::byte> buffer;  // bytes read, not yet delivered
    std::size_t filled = 0;         // [B] in buffer
    std::size_t delivered = 0;      // [B] at the front handed out by the last chunk
  };
  void close();
  bool deliver(std::uint32_t channel, RawChunk& chunk);

  std::string name_;
  RealsenseImuSourceConfig config_;
  Channel channels_[2];
  bool lost_ = false;
  RealsenseImuSourceCounters imu_counters_;
  std::atomic<bool> stop_{false};
  AtomicSourceCounters counts_;
};

}  // namespace posed::drivers::camera
