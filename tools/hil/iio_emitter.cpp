#include "tools/hil/iio_emitter.hpp"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "drivers/camera/iio_scan.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::hil {

namespace fs = std::filesystem;

namespace {

bool write_text(const fs::path& path, const std::string& text, std::string& error) {
  std::ofstream out(path, std::ios::trunc);
  out << text << '\n';
  if (!out) {
    error = "cannot write " + path.string();
    return false;
  }
  return true;
}

}  // namespace

IioEmitter::~IioEmitter() {
  for (Device& d : devices_) {
    if (d.fd >= 0) ::close(d.fd);
  }
}

bool IioEmitter::add(std::string_view wire_format, std::string& error) {
  namespace wire = drivers::wire;
  const bool accel = wire_format.starts_with(wire::kIioAccel3d);
  if (!accel && !wire_format.starts_with(wire::kIioGyro3d)) {
    error = "iio " + dir_ + ": not an IIO HID wire format: " + std::string(wire_format);
    return false;
  }
  Device& device = devices_[accel ? 0 : 1];
  if (device.fd >= 0) return true;
  drivers::camera::IioScanLayout layout;
  if (!drivers::camera::parse_iio_layout(wire_format, accel ? wire::kIioAccel3d : wire::kIioGyro3d,
                                         layout, error)) {
    error = "iio " + dir_ + ": " + error;
    return false;
  }
  const std::string node = accel ? "iio:device0" : "iio:device1";
  const std::string stem = accel ? "in_accel" : "in_anglvel";
  const fs::path sys = fs::path(dir_) / "sys" / node, dev = fs::path(dir_) / "dev" / node;
  std::error_code ec;
  fs::remove_all(sys, ec);
  fs::remove(dev, ec);
  fs::create_directories(sys / "scan_elements", ec);
  fs::create_directories(sys / "buffer", ec);
  fs::create_directories(dev.parent_path(), ec);
  if (ec) {
    error = "iio " + dir_ + ": cannot make " + sys.string() + ": " + ec.message();
    return false;
  }
  bool ok = write_text(sys / "name", accel ? "accel_3d" : "gyro_3d", error) &&
            write_text(sys / "buffer" / "enable", "0", error) &&
            write_text(sys / "buffer" / "length", "2", error) &&
            write_text(sys / (stem + "_sampling_frequency"), "0", error);
  for (const auto& e : layout.elements) {
    ok = ok && write_text(sys / "scan_elements" / (e.name + "_en"), "0", error) &&
         write_text(sys / "scan_elements" / (e.name + "_type"), drivers::camera::to_string(e.type),
                    error) &&
         write_text(sys / "scan_elements" / (e.name + "_index"), std::to_string(e.index), error);
  }
  if (!ok) {
    error = "iio " + dir_ + ": " + error;
    return false;
  }
  if (::mkfifo(dev.c_str(), 0600) != 0) {
    error = "iio " + dir_ + ": cannot make the FIFO " + dev.string() + ": " + std::strerror(errno);
    return false;
  }
  // Read-write, so opening never waits for a reader and the FIFO keeps its bytes between
  // readers, as the kernel's buffer does.
  device.fd = ::open(dev.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (device.fd < 0) {
    error = "iio " + dir_ + ": cannot open " + dev.string() + ": " + std::strerror(errno);
    return false;
  }
  device.wire_format = std::string(wire_format);
  device.record_bytes = layout.record_bytes;
  return true;
}

bool IioEmitter::write(std::string_view wire_format, std::span<const std::byte> bytes) {
  Device* device = nullptr;
  for (Device& d : devices_) {
    if (d.fd >= 0 && d.wire_format == wire_format) device = &d;
  }
  if (device == nullptr || device->record_bytes == 0) return false;
  // Whole records that fit: a FIFO written without blocking may take part of a record.
  const int capacity = ::fcntl(device->fd, F_GETPIPE_SZ);
  int queued = 0;
  if (capacity < 0 || ::ioctl(device->fd, FIONREAD, &queued) != 0) return false;
  const std::size_t room = static_cast<std::size_t>(std::max(0, capacity - queued));
  const std::size_t fit =
      std::min(bytes.size(), room / device->record_bytes * device->record_bytes);
  std::size_t written = 0;
  while (written < fit) {
    const ssize_t n = ::write(device->fd, bytes.data() + written, fit - written);
    if (n <= 0) break;
    written += static_cast<std::size_t>(n);
  }
  writes_.fetch_add(1, std::memory_order_relaxed);
  bytes_.fetch_add(written, std::memory_order_relaxed);
  bytes_dropped_.fetch_add(bytes.size() - written, std::memory_order_relaxed);
  return written == bytes.size();
}

IioCounters IioEmitter::counters() const {
  return {writes_.load(std::memory_order_relaxed), bytes_.load(std::memory_order_relaxed),
          bytes_dropped_.load(std::memory_order_relaxed)};
}

}  // namespace posed::hil
