#include "drivers/camera/v4l2_device.hpp"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>

namespace posed::drivers::camera {
namespace {

class SystemV4l2Device final : public V4l2Device {
 public:
  int open(const char* path, int flags) override { return ::open(path, flags); }
  int close(int fd) override { return ::close(fd); }
  int ioctl(int fd, unsigned long request, void* arg) override {
    int rc;
    // A signal during a blocking ioctl is not a failure (v4l2 capture example, "xioctl").
    do {
      rc = ::ioctl(fd, request, arg);
    } while (rc == -1 && errno == EINTR);
    return rc;
  }
  void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset) override {
    return ::mmap(nullptr, length, prot, flags, fd, offset);
  }
  int munmap(void* addr, std::size_t length) override { return ::munmap(addr, length); }
  int poll(pollfd* fds, nfds_t nfds, int timeout_ms) override {
    return ::poll(fds, nfds, timeout_ms);
  }
};

}  // namespace

V4l2Device& system_v4l2_device() {
  static SystemV4l2Device device;
  return device;
}

}  // namespace posed::drivers::camera
