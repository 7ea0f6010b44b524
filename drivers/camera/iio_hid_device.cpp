#include "drivers/camera/iio_hid_device.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <vector>

#include "drivers/common/log.hpp"

namespace posed::drivers::camera {
namespace {

namespace fs = std::filesystem;

/// A sysfs attribute's first line; false with `error` when unreadable.
bool read_attribute(const fs::path& path, std::string& value, std::string& error) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    error = "cannot read " + path.string() + ": " + std::strerror(errno);
    return false;
  }
  char buf[256];
  const ssize_t n = ::read(fd, buf, sizeof buf - 1);
  const int err = errno;
  ::close(fd);
  if (n < 0) {
    error = "cannot read " + path.string() + ": " + std::strerror(err);
    return false;
  }
  value.assign(buf, static_cast<std::size_t>(n));
  if (const auto nl = value.find('\n'); nl != std::string::npos) value.resize(nl);
  return true;
}

bool write_attribute(const fs::path& path, const std::string& value, std::string& error) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (fd < 0) {
    error = "cannot write " + path.string() + ": " + std::strerror(errno);
    return false;
  }
  const ssize_t n = ::write(fd, value.data(), value.size());
  const int err = errno;
  ::close(fd);
  if (n != static_cast<ssize_t>(value.size())) {
    error = "cannot write '" + value + "' to " + path.string() + ": " +
            (n < 0 ? std::strerror(err) : "short write");
    return false;
  }
  return true;
}

bool find_device(const IioHidDeviceConfig& c, fs::path& dir, std::string& error) {
  if (!c.device_dir.empty()) {
    dir = fs::path(c.sysfs_root) / c.device_dir;
    std::string name;
    if (!read_attribute(dir / "name", name, error)) return false;
    if (name != c.name) {
      error = "IIO device " + dir.string() + " is '" + name + "', not '" + c.name + "'";
      return false;
    }
    return true;
  }
  std::error_code ec;
  std::vector<fs::path> candidates;
  for (const auto& e : fs::directory_iterator(c.sysfs_root, ec)) {
    if (e.path().filename().string().rfind("iio:device", 0) == 0) candidates.push_back(e.path());
  }
  if (ec) {
    error = "cannot list " + c.sysfs_root + ": " + ec.message() + " (no IIO devices)";
    return false;
  }
  std::sort(candidates.begin(), candidates.end());
  for (const auto& p : candidates) {
    std::string name, ignored;
    if (read_attribute(p / "name", name, ignored) && name == c.name) {
      dir = p;
      return true;
    }
  }
  error = "no IIO device named '" + c.name + "' under " + c.sysfs_root +
          " (D435i IMU not connected, or hid-sensor-hub not loaded)";
  return false;
}

bool read_scan_elements(const fs::path& dir, std::vector<IioScanElement>& out, std::string& error) {
  const fs::path scan = dir / "scan_elements";
  std::error_code ec;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(scan, ec)) {
    const std::string f = e.path().filename().string();
    if (f.rfind("in_", 0) == 0 && f.size() > 3 && f.compare(f.size() - 3, 3, "_en") == 0) {
      names.push_back(f.substr(0, f.size() - 3));
    }
  }
  if (ec) {
    error = "cannot list " + scan.string() + ": " + ec.message();
    return false;
  }
  for (const auto& n : names) {
    // librealsense enables every input (iio_hid_sensor::init: input->enable(true)).
    if (!write_attribute(scan / (n + "_en"), "1", error)) return false;
    IioScanElement el;
    el.name = n;
    std::string text;
    if (!read_attribute(scan / (n + "_type"), text, error)) return false;
    if (!parse_iio_scan_type(text, el.type)) {
      error = (scan / (n + "_type")).string() + ": cannot parse scan type '" + text + "'";
      return false;
    }
    if (!read_attribute(scan / (n + "_index"), text, error)) return false;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), el.index);
    if (r.ec != std::errc{}) {
      error = (scan / (n + "_index")).string() + ": not an index: '" + text + "'";
      return false;
    }
    out.push_back(std::move(el));
  }
  return true;
}

std::string format_rate(double hz) {
  char buf[32];
  if (hz == static_cast<double>(static_cast<long long>(hz))) {
    std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(hz));
  } else {
    std::snprintf(buf, sizeof buf, "%.6f", hz);
  }
  return buf;
}

}  // namespace

bool enable_iio_hid_device(const IioHidDeviceConfig& c, IioHidDevice& out, std::string& error) {
  fs::path dir;
  if (!find_device(c, dir, error)) return false;
  out = {};
  out.sysfs_dir = dir.string();
  out.dev_node = (fs::path(c.dev_dir) / dir.filename()).string();
  std::string ignored;
  // Scan elements and buffer/length are refused (EBUSY) while the buffer runs.
  write_attribute(dir / "buffer" / "enable", "0", ignored);
  std::vector<IioScanElement> elements;
  if (!read_scan_elements(dir, elements, error)) return false;
  if (!layout_iio_scan(std::move(elements), out.layout, error)) {
    error = out.sysfs_dir + ": " + error;
    return false;
  }
  if (c.sampling_frequency_hz > 0) {
    std::error_code ec;
    fs::path rate_attr;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      const std::string f = e.path().filename().string();
      if (!e.is_directory() && f.find("sampling_frequency") != std::string::npos &&
          f.find("available") == std::string::npos) {
        rate_attr = e.path();
        break;
      }
    }
    if (rate_attr.empty()) {
      error = out.sysfs_dir + ": no sampling_frequency attribute to set " +
              format_rate(c.sampling_frequency_hz) + " Hz";
      return false;
    }
    if (!write_attribute(rate_attr, format_rate(c.sampling_frequency_hz), error)) return false;
  }
  if (!write_attribute(dir / "buffer" / "length", std::to_string(c.buffer_length), error)) {
    return false;
  }
  // Records queued while the device was enumerated are stale (librealsense clear_buffer()).
  if (const int fd = ::open(out.dev_node.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC); fd >= 0) {
    std::vector<char> sink(4096);
    while (::read(fd, sink.data(), sink.size()) > 0) {
    }
    ::close(fd);
  }
  return write_attribute(dir / "buffer" / "enable", "1", error);
}

void disable_iio_hid_device(const IioHidDevice& device) {
  std::string ignored;
  if (!device.sysfs_dir.empty()) {
    write_attribute(fs::path(device.sysfs_dir) / "buffer" / "enable", "0", ignored);
  }
}

}  // namespace posed::drivers::camera
