#include "drivers/camera/libusb_transport.hpp"

#include <libusb.h>

#include <cstdio>

namespace posed::drivers::camera {

struct LibusbTransport::Impl {
  libusb_context* ctx = nullptr;
  libusb_device_handle* handle = nullptr;
  int interface_number = -1;
  unsigned char ep_out = 0, ep_in = 0;
  int bus = 0, address = 0;

  ~Impl() {
    if (handle != nullptr) {
      if (interface_number >= 0) libusb_release_interface(handle, interface_number);
      libusb_close(handle);
    }
    if (ctx != nullptr) libusb_exit(ctx);
  }
};

namespace {

std::string id_text(const LibusbTransportConfig& c) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "usb %04x:%04x", c.vendor_id, c.product_id);
  return c.serial.empty() ? buf : std::string(buf) + " serial " + c.serial;
}

/// The first vendor-specific interface with a bulk OUT and a bulk IN endpoint.
bool find_hwm_interface(libusb_device* dev, LibusbTransport::Impl& impl) {
  libusb_config_descriptor* cfg = nullptr;
  if (libusb_get_active_config_descriptor(dev, &cfg) != 0) return false;
  bool found = false;
  for (int i = 0; i < cfg->bNumInterfaces && !found; ++i) {
    for (int a = 0; a < cfg->interface[i].num_altsetting && !found; ++a) {
      const libusb_interface_descriptor& d = cfg->interface[i].altsetting[a];
      if (d.bInterfaceClass != LIBUSB_CLASS_VENDOR_SPEC) continue;
      unsigned char out = 0, in = 0;
      for (int e = 0; e < d.bNumEndpoints; ++e) {
        const libusb_endpoint_descriptor& ep = d.endpoint[e];
        if ((ep.bmAttributes & LIBUSB_TRANSFER_TYPE_MASK) != LIBUSB_TRANSFER_TYPE_BULK) continue;
        const bool is_in = (ep.bEndpointAddress & LIBUSB_ENDPOINT_DIR_MASK) == LIBUSB_ENDPOINT_IN;
        if (is_in && in == 0) in = ep.bEndpointAddress;
        if (!is_in && out == 0) out = ep.bEndpointAddress;
      }
      if (in != 0 && out != 0) {
        impl.interface_number = d.bInterfaceNumber;
        impl.ep_in = in;
        impl.ep_out = out;
        found = true;
      }
    }
  }
  libusb_free_config_descriptor(cfg);
  return found;
}

}  // namespace

LibusbTransport::LibusbTransport(LibusbTransportConfig config) : config_(std::move(config)) {}
LibusbTransport::~LibusbTransport() = default;

std::string LibusbTransport::describe() const {
  std::string s = id_text(config_);
  if (impl_ != nullptr && impl_->handle != nullptr) {
    s += " (bus " + std::to_string(impl_->bus) + " device " + std::to_string(impl_->address) +
         ", interface " + std::to_string(impl_->interface_number) + ")";
  }
  return s;
}

bool LibusbTransport::open(std::string& error) {
  if (impl_ != nullptr && impl_->handle != nullptr) return true;
  impl_ = std::make_unique<Impl>();
  const std::string who = id_text(config_);
  if (const int rc = libusb_init(&impl_->ctx); rc != 0) {
    error = who + ": libusb_init failed: " + libusb_strerror(rc);
    impl_.reset();
    return false;
  }
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(impl_->ctx, &list);
  if (n < 0) {
    error = who + ": cannot list USB devices: " + libusb_strerror(static_cast<int>(n));
    impl_.reset();
    return false;
  }
  int last_rc = 0;
  bool seen = false;
  for (ssize_t i = 0; i < n && impl_->handle == nullptr; ++i) {
    libusb_device_descriptor desc{};
    if (libusb_get_device_descriptor(list[i], &desc) != 0 || desc.idVendor != config_.vendor_id ||
        desc.idProduct != config_.product_id) {
      continue;
    }
    seen = true;
    libusb_device_handle* h = nullptr;
    last_rc = libusb_open(list[i], &h);
    if (last_rc != 0) continue;
    if (!config_.serial.empty()) {
      unsigned char serial[128] = {};
      const int len =
          libusb_get_string_descriptor_ascii(h, desc.iSerialNumber, serial, sizeof serial);
      if (len <= 0 || config_.serial != reinterpret_cast<const char*>(serial)) {
        libusb_close(h);
        continue;
      }
    }
    if (!find_hwm_interface(list[i], *impl_)) {
      libusb_close(h);
      continue;
    }
    impl_->handle = h;
    impl_->bus = libusb_get_bus_number(list[i]);
    impl_->address = libusb_get_device_address(list[i]);
  }
  libusb_free_device_list(list, 1);
  if (impl_->handle == nullptr) {
    if (!seen) {
      error = who + ": no such USB device connected";
    } else if (last_rc == LIBUSB_ERROR_ACCESS) {
      error = who +
              ": permission denied opening it (install the udev rule giving the posed user "
              "access to Intel RealSense devices)";
    } else if (last_rc != 0) {
      error = who + ": cannot open: " + libusb_strerror(last_rc);
    } else {
      error = who +
              ": no vendor-specific interface with bulk endpoints (not a D4xx, or serial "
              "mismatch)";
    }
    impl_.reset();
    return false;
  }
  // uvcvideo owns the video interfaces, not this one; detach anyway should a driver hold it.
  libusb_set_auto_detach_kernel_driver(impl_->handle, 1);
  if (const int rc = libusb_claim_interface(impl_->handle, impl_->interface_number); rc != 0) {
    error = describe() + ": cannot claim the HW-monitor interface: " + libusb_strerror(rc);
    impl_->interface_number = -1;
    impl_.reset();
    return false;
  }
  return true;
}

std::ptrdiff_t LibusbTransport::transact(std::span<const std::byte> command,
                                         std::span<std::byte> reply, int timeout_ms,
                                         std::string& error) {
  if (impl_ == nullptr || impl_->handle == nullptr) {
    error = id_text(config_) + ": not open";
    return -1;
  }
  int done = 0;
  int rc = libusb_bulk_transfer(
      impl_->handle, impl_->ep_out,
      const_cast<unsigned char*>(reinterpret_cast<const unsigned char*>(command.data())),
      static_cast<int>(command.size()), &done, static_cast<unsigned>(timeout_ms));
  if (rc != 0 || done != static_cast<int>(command.size())) {
    error = describe() + ": bulk OUT failed: " + (rc != 0 ? libusb_strerror(rc) : "short write");
    return -1;
  }
  rc = libusb_bulk_transfer(
      impl_->handle, impl_->ep_in, reinterpret_cast<unsigned char*>(reply.data()),
      static_cast<int>(reply.size()), &done, static_cast<unsigned>(timeout_ms));
  if (rc != 0) {
    error = describe() + ": bulk IN failed: " + libusb_strerror(rc);
    return -1;
  }
  return done;
}

}  // namespace posed::drivers::camera
