// The live serial Source against a fake A9 on a pty: real termios, poll and read paths, with
// frames paced at the A9's 150 Hz, split across writes, mixed with garbage and bad CRCs.

#include "drivers/imu/serial_source.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>
#include <vector>

#include "drivers/common/host_clock.hpp"
#include "drivers/imu/a9_protocol.hpp"
#include "tests/unit/imu/fake_a9_pty.hpp"

namespace posed::drivers {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

class TempDir {
 public:
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "posed-a9-XXXXXX").string();
    path_ = ::mkdtemp(tmpl.data());
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

Bytes sensor_frame(std::uint32_t counter) {
  const a9::A9SensorFrame f = a9::a9_frame_from_si(Eigen::Vector3d(0.01, -0.02, 0.03 * counter),
                                                   Eigen::Vector3d(0.1, 0.2, 9.80665),
                                                   Eigen::Vector3d(0.08, -0.03, 0.79), counter);
  Bytes b(a9::kSensorFrameSize);
  b.resize(a9::encode_a9_sensor_frame(f, b));
  return b;
}

struct Decoded {
  std::vector<std::uint32_t> counters;
  a9::A9Decoder decoder;
};

/// Reads until `want` frames were decoded or `limit` passed.
void read_until(SerialSource& source, Decoded& out, std::size_t want,
                std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (out.counters.size() < want && std::chrono::steady_clock::now() < end) {
    RawChunk chunk;
    const ReadStatus s = source.read(chunk, Duration::from_ms(50));
    if (s != ReadStatus::kData) continue;
    const std::span<const std::uint8_t> bytes(
        reinterpret_cast<const std::uint8_t*>(chunk.bytes.data()), chunk.bytes.size());
    out.decoder.feed(bytes,
                     [&](const a9::A9Frame& f) { out.counters.push_back(f.sensor.counter_us); });
  }
}

TEST(SerialSource, RejectsUnsupportedBaudAndMissingDevice) {
  std::string error;
  SerialSource bad_baud(SerialConfig{.path = "/dev/null", .baud = 12345});
  EXPECT_FALSE(bad_baud.open(error));
  EXPECT_NE(error.find("12345"), std::string::npos) << error;

  SerialSource missing(SerialConfig{.path = "/nonexistent/ttyA9"});
  EXPECT_FALSE(missing.open(error));
  EXPECT_NE(error.find("/nonexistent/ttyA9"), std::string::npos) << error;

  SerialSource not_tty(SerialConfig{.path = "/dev/null"});
  EXPECT_FALSE(not_tty.open(error));
  EXPECT_NE(error.find("not a tty"), std::string::npos) << error;
}

TEST(SerialSource, StreamsAt150HzWithSplitsGarbageAndBadCrc) {
  TempDir dir;
  const auto link = dir.path() / "usb-Handsfree_A9-if00-port0";
  test::FakeA9Pty pty(link);
  SerialSource source(SerialConfig{.path = link.string()});
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  pty.release_slave();

  // The script: 150 frames (1 s at 150 Hz). Every 10th frame (from #3) has a broken CRC, every
  // 7th is preceded by garbage (never 0xAA, so the skipped count is exact), and each frame is
  // written in two pieces split at a different byte.
  constexpr std::uint32_t kFrames = 150;
  std::vector<std::uint32_t> expected;
  std::uint64_t garbage_bytes = 0, corrupted = 0;
  std::vector<std::pair<Bytes, Bytes>> writes;
  for (std::uint32_t i = 0; i < kFrames; ++i) {
    Bytes pre;
    if (i % 7 == 0) {
      pre = {0x00, 0x55, 0x13, 0xFF, static_cast<std::uint8_t>(i)};
      garbage_bytes += pre.size();
    }
    Bytes frame = sensor_frame(1'000'000 + i * 6667);
    if (i % 10 == 3) {
      frame.back() ^= 0x5A;
      ++corrupted;
    } else {
      expected.push_back(1'000'000 + i * 6667);
    }
    frame.insert(frame.begin(), pre.begin(), pre.end());
    const std::size_t cut = 1 + i % (frame.size() - 1);
    writes.emplace_back(Bytes(frame.begin(), frame.begin() + static_cast<long>(cut)),
                        Bytes(frame.begin() + static_cast<long>(cut), frame.end()));
  }

  std::atomic<bool> write_ok{true};
  std::thread writer([&] {
    auto next = std::chrono::steady_clock::now();
    for (const auto& [a, b] : writes) {
      std::this_thread::sleep_until(next);
      write_ok = write_ok && pty.write_all(a);
      std::this_thread::sleep_for(300us);  // lets the reader see the frame in two reads
      write_ok = write_ok && pty.write_all(b);
      next += std::chrono::microseconds(1'000'000 / 150);
    }
  });

  Decoded got;
  read_until(source, got, expected.size(), 5000ms);
  writer.join();
  // Anything after the last good frame (a trailing bad one) arrives within a few reads.
  for (int k = 0; k < 5; ++k) {
    RawChunk chunk;
    if (source.read(chunk, Duration::from_ms(20)) == ReadStatus::kData) {
      got.decoder.feed(
          {reinterpret_cast<const std::uint8_t*>(chunk.bytes.data()), chunk.bytes.size()},
          [&](const a9::A9Frame& f) { got.counters.push_back(f.sensor.counter_us); });
    }
  }
  ASSERT_TRUE(write_ok);

  EXPECT_EQ(got.counters, expected);
  const auto& c = got.decoder.counters();
  EXPECT_EQ(c.bad_crc, corrupted);
  EXPECT_EQ(c.truncated, 0u);
  EXPECT_EQ(c.skipped_bytes, garbage_bytes + corrupted * a9::kSensorFrameSize);
  const SourceCounters sc = source.counters();
  EXPECT_EQ(sc.bytes, kFrames * a9::kSensorFrameSize + garbage_bytes);
  // How many reads the split writes arrive in depends on scheduling (a loaded machine coalesces
  // them); frames split at every byte are covered deterministically in a9_protocol_test.
  EXPECT_EQ(sc.reopened, 0u);
}

TEST(SerialSource, ReopensAfterUnplug) {
  TempDir dir;
  const auto link = dir.path() / "a9";
  test::FakeA9Pty pty(link);
  SerialConfig cfg{.path = link.string()};
  cfg.reopen_backoff_min = Duration::from_ms(20);
  cfg.reopen_backoff_max = Duration::from_ms(80);
  SerialSource source(cfg);
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  pty.release_slave();

  for (std::uint32_t i = 0; i < 20; ++i) ASSERT_TRUE(pty.write_all(sensor_frame(i)));
  Decoded got;
  read_until(source, got, 20, 3000ms);
  ASSERT_EQ(got.counters.size(), 20u);

  pty.unplug();
  int lost = 0;
  // While unplugged, reads report the loss and come back within their timeout.
  for (int k = 0; k < 4; ++k) {
    RawChunk chunk;
    const auto t0 = host_now();
    const ReadStatus s = source.read(chunk, Duration::from_ms(30));
    EXPECT_LT((host_now() - t0).ns, Duration::from_ms(200).ns);
    if (s == ReadStatus::kDeviceLost) ++lost;
  }
  EXPECT_GT(lost, 0);
  EXPECT_FALSE(source.is_open());
  EXPECT_GT(source.reopen_attempts(), 0u);  // the dangling link failed to open at least once

  ASSERT_TRUE(pty.plug()) << "second openpty failed";
  // The Source flushes stale input on open, so write only once it is back.
  for (int k = 0; k < 50 && !source.is_open(); ++k) {
    RawChunk chunk;
    source.read(chunk, Duration::from_ms(20));
  }
  ASSERT_TRUE(source.is_open());
  EXPECT_EQ(source.counters().reopened, 1u);
  pty.release_slave();
  for (std::uint32_t i = 20; i < 40; ++i) ASSERT_TRUE(pty.write_all(sensor_frame(i)));
  read_until(source, got, 40, 3000ms);
  std::vector<std::uint32_t> expected;
  for (std::uint32_t i = 0; i < 40; ++i) expected.push_back(i);
  EXPECT_EQ(got.counters, expected);
}

TEST(SerialSource, RequestStopWakesBlockedRead) {
  TempDir dir;
  const auto link = dir.path() / "a9";
  test::FakeA9Pty pty(link);
  SerialSource source(SerialConfig{.path = link.string()});
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  std::thread stopper([&] {
    std::this_thread::sleep_for(50ms);
    source.request_stop();
  });
  RawChunk chunk;
  const auto t0 = host_now();
  EXPECT_EQ(source.read(chunk, Duration::from_s(10)), ReadStatus::kEndOfStream);
  EXPECT_LT((host_now() - t0).ns, Duration::from_s(2).ns);
  stopper.join();
  EXPECT_EQ(source.read(chunk, Duration::from_ms(1)), ReadStatus::kEndOfStream);
}

}  // namespace
}  // namespace posed::drivers
