#pragma once
// What the recording, hardware-in-the-loop and ROS 2 tool tests share: a DDS domain of their own
// and free UDP and TCP ports for a live posed to listen on.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <string>

#include "tests/integration/posed_process.hpp"

namespace posed::testing::hil_helpers {

// 1..99 like the other integration tests; +75 keeps these apart from the daemon (+0), lio (+25)
// and replay (+50) tests of a process with the same id.
inline int test_domain() { return 1 + static_cast<int>((::getpid() + 75) % 99); }

/// A port of `type` (SOCK_DGRAM, SOCK_STREAM) nobody uses on loopback right now (the kernel's
/// pick of an ephemeral port, released again).
inline std::uint16_t free_port(int type) {
  const int fd = ::socket(AF_INET, type | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}
inline std::uint16_t free_udp_port() { return free_port(SOCK_DGRAM); }
inline std::uint16_t free_tcp_port() { return free_port(SOCK_STREAM); }

/// The DDS part of a live posed's config: loopback DDS on the test's domain.
inline std::string dds_config() { return loopback_dds_yaml(test_domain()); }

/// The number after `label` in `text` (e.g. "udp data            22605 packets"), or -1.
inline long long number_after(const std::string& text, const std::string& label) {
  const auto at = text.find(label);
  if (at == std::string::npos) return -1;
  return std::atoll(text.c_str() + at + label.size());
}

}  // namespace posed::testing::hil_helpers
