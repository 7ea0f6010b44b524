// UdpEmitter on loopback: HOST:PORT[,POSITION_PORT] parsing, data and position packets to their
// own ports byte for byte, and sends to a port nobody listens on neither fail nor stop emission.

#include "tools/hil/udp_emitter.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <vector>

#include "tests/unit/hil/recording_builder.hpp"

namespace posed::hil {
namespace udp_emitter_test {

/// A bound loopback UDP socket on an ephemeral port.
class Receiver {
 public:
  Receiver() {
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    socklen_t len = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
  }
  ~Receiver() { ::close(fd_); }
  std::uint16_t port() const { return port_; }
  /// The next datagram within 2 s (empty when none came) and the sender's address.
  std::vector<std::byte> receive(std::string* from = nullptr) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 2000) != 1) return {};
    std::vector<std::byte> buf(2048);
    sockaddr_in src{};
    socklen_t len = sizeof src;
    const ssize_t n =
        ::recvfrom(fd_, buf.data(), buf.size(), 0, reinterpret_cast<sockaddr*>(&src), &len);
    if (from != nullptr) {
      char text[INET_ADDRSTRLEN] = {};
      ::inet_ntop(AF_INET, &src.sin_addr, text, sizeof text);
      *from = text;
    }
    buf.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
    return buf;
  }

 private:
  int fd_ = -1;
  std::uint16_t port_ = 0;
};

TEST(UdpTarget, ParsesHostPortAndOptionalPositionPort) {
  UdpTarget t;
  std::string error;
  ASSERT_TRUE(parse_udp_target("192.168.1.77:2368", t, error)) << error;
  EXPECT_EQ(t.host, "192.168.1.77");
  EXPECT_EQ(t.data_port, 2368);
  EXPECT_EQ(t.position_port, 8308);
  ASSERT_TRUE(parse_udp_target("localhost:4000,4001", t, error)) << error;
  EXPECT_EQ(t.host, "localhost");
  EXPECT_EQ(t.data_port, 4000);
  EXPECT_EQ(t.position_port, 4001);
}

TEST(UdpTarget, RejectsMalformedTargetsSayingWhy) {
  UdpTarget t;
  std::string error;
  for (const char* bad :
       {"2368", "host:", ":2368", "host:0", "host:70000", "host:2368,x", "host:23a8"}) {
    error.clear();
    EXPECT_FALSE(parse_udp_target(bad, t, error)) << bad;
    EXPECT_NE(error.find(bad), std::string::npos) << error;
  }
}

TEST(UdpEmitter, DataAndPositionGoToTheirPortsByteForByte) {
  Receiver data, position;
  UdpEmitter e({"127.0.0.1", data.port(), position.port()});
  std::string error;
  ASSERT_TRUE(e.open(error)) << error;
  const auto packet = test::payload(1, 7, 1206);
  const auto gprmc = test::payload(2, 9, 512);
  ASSERT_TRUE(e.send(0, packet));
  ASSERT_TRUE(e.send(1, gprmc));
  std::string from;
  EXPECT_EQ(data.receive(&from), packet);
  EXPECT_EQ(from, "127.0.0.1");  // what posed's lidar.address must name
  EXPECT_EQ(position.receive(), gprmc);
  EXPECT_EQ(e.counters(0).datagrams, 1u);
  EXPECT_EQ(e.counters(0).bytes, 1206u);
  EXPECT_EQ(e.counters(1).datagrams, 1u);
  EXPECT_EQ(e.counters(1).bytes, 512u);
  EXPECT_FALSE(e.send(2, packet));  // no third port
  EXPECT_EQ(e.destination(0), "127.0.0.1:" + std::to_string(data.port()));
}

TEST(UdpEmitter, NobodyListeningIsNotAnError) {
  std::uint16_t closed_port = 0;
  {
    Receiver gone;  // bound, then closed: nothing listens on the port any more
    closed_port = gone.port();
  }
  UdpEmitter e({"127.0.0.1", closed_port, closed_port});
  std::string error;
  ASSERT_TRUE(e.open(error)) << error;
  const auto packet = test::payload(1, 0, 1206);
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(e.send(0, packet)) << i;
  EXPECT_EQ(e.counters(0).datagrams, 5u);
  EXPECT_EQ(e.counters(0).failed, 0u);
}

TEST(UdpEmitter, AnUnresolvableHostIsAnOpenErrorNamingIt) {
  UdpEmitter e({"no-such-host.invalid", 2368, 8308});
  std::string error;
  EXPECT_FALSE(e.open(error));
  EXPECT_NE(error.find("no-such-host.invalid"), std::string::npos) << error;
}

}  // namespace udp_emitter_test
}  // namespace posed::hil
