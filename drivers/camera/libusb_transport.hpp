#pragma once
// UsbTransport over libusb-1.0 to a RealSense D4xx's HW-monitor interface, found as
// librealsense's command_transfer_usb finds it (src/platform/command-transfer.h): the first
// interface of class 0xFF (vendor specific; interface 6 on the D435i per
// ds::d400_try_fetch_usb_device), its first bulk OUT and first bulk IN endpoints. libusb.h stays
// in the .cpp.

#include <cstdint>
#include <memory>
#include <string>

#include "drivers/camera/usb_transport.hpp"

namespace posed::drivers::camera {

struct LibusbTransportConfig {
  std::uint16_t vendor_id = 0x8086;   ///< Intel
  std::uint16_t product_id = 0x0B3A;  ///< D435i (ds::RS435I_PID)
  /// iSerialNumber to pick one camera among several; empty = the first found
  std::string serial;
};

class LibusbTransport final : public UsbTransport {
 public:
  explicit LibusbTransport(LibusbTransportConfig config = {});
  ~LibusbTransport() override;
  bool open(std::string& error) override;
  std::ptrdiff_t transact(std::span<const std::byte> command, std::span<std::byte> reply,
                          int timeout_ms, std::string& error) override;
  std::string describe() const override;

  struct Impl;

 private:
  LibusbTransportConfig config_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace posed::drivers::camera
