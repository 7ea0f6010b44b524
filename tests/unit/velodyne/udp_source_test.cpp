// The live UDP Source over loopback: a sender replays the real capture at 10× its recorded
// timing and the Source must deliver every datagram, byte for byte; foreign senders and
// oversized datagrams are counted and dropped; stop wakes a blocked read.

#include "drivers/velodyne/udp_source.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "drivers/velodyne/packet_decoder.hpp"
#include "tests/common/realdata.hpp"
#include "tests/unit/velodyne/capture_fixture.hpp"

namespace posed::drivers::velodyne {
namespace {

class Sender {
 public:
  explicit Sender(const char* from = "127.0.0.1") {
    fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    ::inet_pton(AF_INET, from, &a.sin_addr);
    ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }
  ~Sender() { ::close(fd_); }
  bool send(std::span<const std::byte> bytes, std::uint16_t port) {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    ::inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
    return ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to),
                    sizeof to) == static_cast<ssize_t>(bytes.size());
  }

 private:
  int fd_ = -1;
};

UdpSourceConfig loopback_config() {
  UdpSourceConfig c;
  c.sensor_address = "127.0.0.1";
  c.bind_address = "127.0.0.1";
  c.data_port = 0;
  c.position_port = 0;
  return c;
}

TEST(UdpSource, LoopbackReplayAtTenTimesLosesNothing) {
  POSED_REQUIRE_REALDATA(pcap, "velodyne_vlp32c/vlp32c_nebula_5scans.pcap");
  const auto datagrams = test::load_datagrams(pcap);
  ASSERT_EQ(datagrams.size(), 379u);
  UdpSource source(loopback_config());
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  const std::uint16_t data_port = source.bound_port(0);
  const std::uint16_t position_port = source.bound_port(1);
  ASSERT_NE(data_port, 0);
  ASSERT_NE(position_port, 0);
  EXPECT_GE(source.stats().receive_buffer_bytes, 4u * 1024 * 1024);

  std::vector<std::byte> position(512, std::byte{0});
  std::thread sender_thread([&] {
    Sender sender;
    const auto t0 = std::chrono::steady_clock::now();
    const std::int64_t first = datagrams.front().timestamp_ns;
    for (std::size_t i = 0; i < datagrams.size(); ++i) {
      const auto due = t0 + std::chrono::nanoseconds((datagrams[i].timestamp_ns - first) / 10);
      std::this_thread::sleep_until(due);
      sender.send(datagrams[i].payload, data_port);
      if (i % 100 == 0) sender.send(position, position_port);
    }
  });

  PacketDecoder decoder;
  auto out = std::make_unique<DecodedPacket>();
  std::size_t data = 0, positions = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while ((data < 379 || positions < 4) && std::chrono::steady_clock::now() < deadline) {
    RawChunk chunk;
    const ReadStatus s = source.read(chunk, Duration::from_ms(100));
    if (s != ReadStatus::kData) continue;
    if (chunk.channel == 0) {
      ASSERT_LT(data, datagrams.size());
      ASSERT_TRUE(std::equal(chunk.bytes.begin(), chunk.bytes.end(),
                             datagrams[data].payload.begin(), datagrams[data].payload.end()))
          << "datagram " << data << " differs or arrived out of order";
      EXPECT_EQ(decoder.decode(chunk.bytes, *out), DecodeStatus::kOk);
      ++data;
    } else {
      EXPECT_EQ(chunk.channel, 1u);
      EXPECT_EQ(chunk.bytes.size(), 512u);
      ++positions;
    }
  }
  sender_thread.join();
  EXPECT_EQ(data, 379u);
  EXPECT_EQ(positions, 4u);
  EXPECT_EQ(source.counters().rejected, 0u);
  EXPECT_EQ(decoder.counters().packets_ok, 379u);
}

TEST(UdpSource, ForeignOversizedAndShortDatagrams) {
  UdpSource source(loopback_config());
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  const std::uint16_t port = source.bound_port(0);
  Sender sensor;
  Sender stranger("127.0.0.2");  // all of 127/8 is loopback on Linux
  std::vector<std::byte> packet(1206, std::byte{0x11});
  EXPECT_TRUE(stranger.send(packet, port));
  EXPECT_TRUE(sensor.send(std::vector<std::byte>(3000, std::byte{0x22}), port));
  EXPECT_TRUE(sensor.send(std::vector<std::byte>(100, std::byte{0x33}), port));
  EXPECT_TRUE(sensor.send(packet, port));
  std::vector<std::size_t> sizes;
  for (int i = 0; i < 20 && sizes.size() < 2; ++i) {
    RawChunk chunk;
    if (source.read(chunk, Duration::from_ms(50)) == ReadStatus::kData) {
      sizes.push_back(chunk.bytes.size());
    }
  }
  // The short one is passed on (the decoder counts it as wrong size); the others are dropped.
  ASSERT_EQ(sizes.size(), 2u);
  EXPECT_EQ(sizes[0], 100u);
  EXPECT_EQ(sizes[1], 1206u);
  EXPECT_EQ(source.stats().foreign, 1u);
  EXPECT_EQ(source.stats().oversized, 1u);
  EXPECT_EQ(source.counters().rejected, 2u);
}

TEST(UdpSource, SilenceIsATimeoutAndStopWakesARead) {
  UdpSource source(loopback_config());
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  RawChunk chunk;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(source.read(chunk, Duration::from_ms(30)), ReadStatus::kTimeout);
  EXPECT_GE(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(25));
  ReadStatus status = ReadStatus::kData;
  std::thread reader([&] { status = source.read(chunk, Duration::from_s(10)); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto t1 = std::chrono::steady_clock::now();
  source.request_stop();
  reader.join();
  EXPECT_EQ(status, ReadStatus::kEndOfStream);
  EXPECT_LT(std::chrono::steady_clock::now() - t1, std::chrono::seconds(2));
}

TEST(UdpSource, BadAddressesFailToOpenWithContext) {
  UdpSourceConfig c = loopback_config();
  c.sensor_address = "not-an-ip";
  UdpSource a(c);
  std::string error;
  EXPECT_FALSE(a.open(error));
  EXPECT_NE(error.find("not-an-ip"), std::string::npos) << error;
  c = loopback_config();
  c.bind_address = "192.0.2.1";  // TEST-NET-1: not a local address
  UdpSource b(c);
  EXPECT_FALSE(b.open(error));
  EXPECT_NE(error.find("bind"), std::string::npos) << error;
}

}  // namespace
}  // namespace posed::drivers::velodyne
