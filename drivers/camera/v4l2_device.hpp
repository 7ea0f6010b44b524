#pragma once
// The thin seam between the V4L2 capture code and the kernel: the six calls it makes, with the
// kernel's conventions (return -1 and set errno). The live implementation forwards to the
// syscalls; tests substitute a scripted fake (memfd-backed buffers, scripted ioctl answers) so
// every capture path runs without /dev/video*. poll() with no descriptors is the one way the
// capture code waits without a device (between reopen attempts), so a fake can skip the wait.

#include <poll.h>
#include <sys/types.h>

#include <cstddef>

namespace posed::drivers::camera {

class V4l2Device {
 public:
  virtual ~V4l2Device() = default;
  /// open(2): a descriptor, or -1 with errno.
  virtual int open(const char* path, int flags) = 0;
  /// close(2)
  virtual int close(int fd) = 0;
  /// ioctl(2) with the V4L2 request codes of linux/videodev2.h.
  virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
  /// mmap(2); MAP_FAILED with errno on failure.
  virtual void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset) = 0;
  /// munmap(2)
  virtual int munmap(void* addr, std::size_t length) = 0;
  /// poll(2); with nfds == 0 it only waits `timeout_ms`.
  virtual int poll(pollfd* fds, nfds_t nfds, int timeout_ms) = 0;
};

/// The live device: the real syscalls (ioctl retried on EINTR).
V4l2Device& system_v4l2_device();

}  // namespace posed::drivers::camera
