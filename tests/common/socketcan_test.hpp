#pragma once
// Live SocketCAN for the hw-labelled tests: which interface to use (POSED_CAN_IFACE, default
// vcan0: `ip link add dev vcan0 type vcan && ip link set up vcan0`), why there is none here, and
// a second raw socket on it to send frames through (vcan loops them back to every reader).

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>

namespace posed::test {

/// Sets `iface` to the interface to test on and returns "", or returns why there is none (for
/// GTEST_SKIP): no PF_CAN in this kernel/container, or no such interface.
inline std::string live_can_interface(std::string& iface) {
  const int probe = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (probe < 0) {
    return "socket(PF_CAN) failed (" + std::string(std::strerror(errno)) +
           "): this kernel/container has no SocketCAN";
  }
  ::close(probe);
  const char* env = std::getenv("POSED_CAN_IFACE");
  iface = env != nullptr ? env : "vcan0";
  if (::if_nametoindex(iface.c_str()) == 0) {
    return "CAN interface " + iface + " not present (set POSED_CAN_IFACE)";
  }
  return {};
}

/// A raw CAN socket bound to `iface` for sending; -1 on failure.
inline int open_can_sender(const std::string& iface) {
  const int fd = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) return -1;
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(::if_nametoindex(iface.c_str()));
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

}  // namespace posed::test
