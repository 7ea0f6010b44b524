#pragma once
// The seam between the D4xx HW-monitor client and USB: one command out on the bulk OUT
// endpoint, one reply in from the bulk IN endpoint. LibusbTransport talks to the camera; tests
// substitute a fake that answers in the camera's wire format.

#include <cstddef>
#include <span>
#include <string>

namespace posed::drivers::camera {

class UsbTransport {
 public:
  virtual ~UsbTransport() = default;
  /// Finds and claims the device's interface. false with `error` saying why (no device, no
  /// permission, interface busy), naming the device.
  virtual bool open(std::string& error) = 0;
  /// Sends `command`, then receives one reply into `reply`. Returns the reply's size, or -1 with
  /// `error` (timeout, device gone).
  virtual std::ptrdiff_t transact(std::span<const std::byte> command, std::span<std::byte> reply,
                                  int timeout_ms, std::string& error) = 0;
  /// "usb 8086:0b3a (bus 2 device 7, interface 6)" or the like, for logs.
  virtual std::string describe() const = 0;
};

}  // namespace posed::drivers::camera
