#include "tools/hil/udp_emitter.hpp"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>

namespace posed::hil {

namespace {

bool parse_port(std::string_view text, std::uint16_t& port) {
  unsigned v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc{} || end != text.data() + text.size() || v == 0 || v > 65535) return false;
  port = static_cast<std::uint16_t>(v);
  return true;
}

}  // namespace

bool parse_udp_target(const std::string& text, UdpTarget& out, std::string& error) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    error = "'" + text + "': expected HOST:PORT[,POSITION_PORT]";
    return false;
  }
  UdpTarget t;
  t.host = text.substr(0, colon);
  const std::string ports = text.substr(colon + 1);
  const auto comma = ports.find(',');
  if (!parse_port(std::string_view(ports).substr(0, comma), t.data_port)) {
    error = "'" + text + "': data port must be a number in 1..65535";
    return false;
  }
  if (comma != std::string::npos &&
      !parse_port(std::string_view(ports).substr(comma + 1), t.position_port)) {
    error = "'" + text + "': position port must be a number in 1..65535";
    return false;
  }
  out = t;
  return true;
}

UdpEmitter::~UdpEmitter() {
  if (fd_ >= 0) ::close(fd_);
}

std::string UdpEmitter::destination(std::uint32_t source_channel) const {
  return target_.host + ":" +
         std::to_string(source_channel == 0 ? target_.data_port : target_.position_port);
}

bool UdpEmitter::open(std::string& error) {
  const std::string where = "udp " + destination(0);
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  const int rc = ::getaddrinfo(target_.host.c_str(), nullptr, &hints, &found);
  if (rc != 0 || found == nullptr) {
    error = where + ": cannot resolve '" + target_.host + "': " + ::gai_strerror(rc);
    return false;
  }
  address_be_ = reinterpret_cast<const sockaddr_in*>(found->ai_addr)->sin_addr.s_addr;
  ::freeaddrinfo(found);
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    error = where + ": socket: " + std::strerror(errno);
    return false;
  }
  // A Velodyne on a LAN often sends to the broadcast address; allow the same.
  const int yes = 1;
  ::setsockopt(fd_, SOL_SOCKET, SO_BROADCAST, &yes, sizeof yes);
  return true;
}

bool UdpEmitter::send(std::uint32_t source_channel, std::span<const std::byte> payload) {
  if (fd_ < 0 || source_channel > 1) return false;
  AtomicCounters& c = counters_[source_channel];
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = address_be_;
  to.sin_port = htons(source_channel == 0 ? target_.data_port : target_.position_port);
  // Blocking send: on loopback or a LAN a datagram leaves at once; a full socket buffer then
  // delays this packet (measured as lateness) instead of losing it.
  const ssize_t n = ::sendto(fd_, payload.data(), payload.size(), 0,
                             reinterpret_cast<const sockaddr*>(&to), sizeof to);
  if (n == static_cast<ssize_t>(payload.size())) {
    c.datagrams.fetch_add(1, std::memory_order_relaxed);
    c.bytes.fetch_add(payload.size(), std::memory_order_relaxed);
    return true;
  }
  c.failed.fetch_add(1, std::memory_order_relaxed);
  last_error_ =
      "sendto " + destination(source_channel) + ": " + std::strerror(n < 0 ? errno : EMSGSIZE);
  return false;
}

UdpChannelCounters UdpEmitter::counters(std::uint32_t source_channel) const {
  if (source_channel > 1) return {};
  const AtomicCounters& c = counters_[source_channel];
  return {c.datagrams.load(std::memory_order_relaxed), c.bytes.load(std::memory_order_relaxed),
          c.failed.load(std::memory_order_relaxed)};
}

}  // namespace posed::hil
