// HilReplay end to end on loopback sockets and a real pty: every message of the recording
// reaches its wire in order and byte for byte, and every one is measured.

#include "tools/hil/hil_replay.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <future>
#include <thread>

#include "tests/unit/hil/recording_builder.hpp"

namespace posed::hil {
namespace hil_replay_test {

using test::RawMessage;

/// A loopback UDP socket that keeps every datagram it gets.
struct Sink {
  Sink() {
    fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
    socklen_t len = sizeof a;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    port = ntohs(a.sin_port);
  }
  ~Sink() { ::close(fd); }
  /// Datagrams until `expected` arrived or none came for 5 s.
  std::vector<std::vector<std::byte>> drain(std::size_t expected) {
    std::vector<std::vector<std::byte>> out;
    while (out.size() < expected) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 5000) != 1) return out;
      std::vector<std::byte> buf(2048);
      const ssize_t n = ::recv(fd, buf.data(), buf.size(), 0);
      if (n < 0) return out;
      buf.resize(static_cast<std::size_t>(n));
      out.push_back(std::move(buf));
    }
    return out;
  }
  int fd = -1;
  std::uint16_t port = 0;
};

TEST(HilReplay, EveryMessageReachesItsWireInOrderAndIsMeasured) {
  test::TempDir dir("replay");
  constexpr std::int64_t kT0 = 5'000'000'000;
  // 200 ms: lidar every 2 ms, imu every 10 ms, position every 100 ms, a camera nobody gets.
  std::vector<RawMessage> messages;
  std::vector<std::vector<std::byte>> lidar, position;
  std::vector<std::byte> serial;
  for (std::uint32_t i = 0; i < 100; ++i) {
    const std::int64_t t = kT0 + i * 2'000'000;
    lidar.push_back(test::payload(1, i, 1206));
    messages.push_back({1, t, lidar.back()});
    if (i % 5 == 0) {
      const auto frame = test::payload(0, i, 49);
      serial.insert(serial.end(), frame.begin(), frame.end());
      messages.push_back({0, t + 1000, frame});
    }
    if (i % 50 == 0) {
      position.push_back(test::payload(2, i, 512));
      messages.push_back({2, t + 2000, position.back()});
    }
    if (i % 33 == 0) messages.push_back({3, t + 3000, test::payload(3, i, 100)});
  }
  std::string error;
  ASSERT_TRUE(test::write_recording(dir.file("r.mcap"), test::rig_channels(), messages, error))
      << error;

  Sink data, pos;
  HilReplayOptions options;
  options.playlist.path = dir.file("r.mcap");
  options.udp = {"127.0.0.1", data.port, pos.port};
  options.pty_link = dir.file("a9");
  options.rate = 4.0;  // 50 ms of sending; the order and the bytes are what is checked here
  HilReplay replay(options);
  ASSERT_TRUE(replay.open(error)) << error;
  ASSERT_NE(replay.pty(), nullptr);
  ASSERT_NE(replay.udp(), nullptr);
  const int reader = ::open(dir.file("a9").c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(reader, 0);
  ASSERT_TRUE(replay.pty()->wait_for_reader(Duration::from_s(5), replay.stop_flag()));

  // Received while they are sent: 100 full-size datagrams overflow a default socket buffer.
  auto lidar_received = std::async(std::launch::async, [&] { return data.drain(lidar.size()); });
  replay.run();

  // Compared as booleans: a mismatch of 100 packets would print megabytes.
  const auto got_lidar = lidar_received.get();
  ASSERT_EQ(got_lidar.size(), lidar.size());
  for (std::size_t i = 0; i < lidar.size(); ++i) EXPECT_TRUE(got_lidar[i] == lidar[i]) << i;
  EXPECT_TRUE(pos.drain(position.size()) == position);
  std::vector<std::byte> got;
  while (got.size() < serial.size()) {
    pollfd p{reader, POLLIN, 0};
    if (::poll(&p, 1, 5000) != 1) break;
    std::byte buf[4096];
    const ssize_t n = ::read(reader, buf, sizeof buf);
    if (n <= 0) break;
    got.insert(got.end(), buf, buf + n);
  }
  ::close(reader);
  ASSERT_EQ(got.size(), serial.size());
  EXPECT_TRUE(got == serial);

  const HilReplayStatus s = replay.status();
  EXPECT_TRUE(s.finished);
  EXPECT_TRUE(s.started);
  EXPECT_EQ(s.anchor_log_ns, kT0);
  EXPECT_EQ(s.last_log_ns, kT0 + 99 * 2'000'000);
  EXPECT_EQ(s.udp_data.datagrams, 100u);
  EXPECT_EQ(s.udp_position.datagrams, 2u);
  EXPECT_EQ(s.pty.writes, 20u);
  EXPECT_EQ(s.pty.bytes, serial.size());
  // kHilOutputs order: UDP data, UDP position, pty, IIO (the recording has no D435i IMU)
  const std::array<std::uint64_t, kHilOutputs.size()> expected = {100, 2, 20, 0};
  for (std::size_t i = 0; i < kHilOutputs.size(); ++i) {
    EXPECT_EQ(s.messages[i], expected[i]) << to_string(kHilOutputs[i]);
    EXPECT_EQ(s.lateness[i].count(), expected[i]) << to_string(kHilOutputs[i]);
  }
}

TEST(HilReplay, StopEndsASendingLoop) {
  test::TempDir dir("replay_stop");
  std::vector<RawMessage> messages;
  for (std::uint32_t i = 0; i < 10; ++i) {
    messages.push_back({0, 1'000'000'000 + i * 100'000'000ll, test::payload(0, i, 1206)});
  }
  std::string error;
  ASSERT_TRUE(test::write_recording(dir.file("r.mcap"), {{"lidar", "velodyne-udp-data", 0, false}},
                                    messages, error))
      << error;
  Sink data;
  HilReplayOptions options;
  options.playlist.path = dir.file("r.mcap");
  options.playlist.loop = true;  // would never end by itself
  options.udp = {"127.0.0.1", data.port, data.port};
  HilReplay replay(options);
  ASSERT_TRUE(replay.open(error)) << error;
  EXPECT_EQ(replay.pty(), nullptr);  // nothing in this recording goes to a pty
  std::thread sender([&] { replay.run(); });
  while (replay.status().messages[0] < 2) std::this_thread::yield();
  replay.request_stop();
  sender.join();
  EXPECT_TRUE(replay.status().finished);
}

}  // namespace hil_replay_test
}  // namespace posed::hil
