// posectl bench imu: A9 parser throughput, and serial Source end-to-end latency from a pty write
// to the decoded sample (the path a live A9 takes, minus the USB adapter).

#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>
#include <vector>

#include "drivers/common/host_clock.hpp"
#include "drivers/imu/a9_protocol.hpp"
#include "drivers/imu/serial_source.hpp"
#include "tools/posectl/bench.hpp"

namespace posed::posectl {
namespace {

namespace a9 = drivers::a9;

std::vector<std::uint8_t> frame_bytes(std::uint32_t counter) {
  const a9::A9SensorFrame f =
      a9::a9_frame_from_si(Eigen::Vector3d(0.01, -0.02, 0.5), Eigen::Vector3d(0.3, -0.1, 9.8),
                           Eigen::Vector3d(0.08, -0.03, 0.79), counter);
  std::vector<std::uint8_t> b(a9::kSensorFrameSize);
  b.resize(a9::encode_a9_sensor_frame(f, b));
  return b;
}

int bench_parser() {
  // 1 MB of sensor frames with a bad CRC every 100th and a few garbage bytes every 50th,
  // fed in 4 KiB pieces like serial reads.
  std::vector<std::uint8_t> stream;
  for (std::uint32_t i = 0; i < 20'000; ++i) {
    auto b = frame_bytes(i * 6667);
    if (i % 100 == 0) b[20] ^= 0xFF;
    if (i % 50 == 0) stream.insert(stream.end(), {0x01, 0x02, 0x03});
    stream.insert(stream.end(), b.begin(), b.end());
  }
  std::uint64_t frames = 0, bytes = 0;
  double checksum = 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto t1 = t0;
  while (t1 - t0 < std::chrono::milliseconds(500)) {
    a9::A9Decoder d;
    for (std::size_t at = 0; at < stream.size(); at += 4096) {
      d.feed(
          std::span(stream).subspan(at, std::min<std::size_t>(4096, stream.size() - at)),
          [&](const a9::A9Frame& f) { checksum += static_cast<double>(f.sensor.gyro_radps[2]); });
    }
    frames += d.counters().frames_ok;
    bytes += stream.size();
    t1 = std::chrono::steady_clock::now();
  }
  const double s = std::chrono::duration<double>(t1 - t0).count();
  if (checksum == 0) return 1;  // keeps the decode from being optimised away
  report("imu", "parser_throughput", static_cast<double>(bytes) / s / 1e6, "MB/s");
  report("imu", "parser_frames", static_cast<double>(frames) / s, "frames/s");
  return 0;
}

int bench_serial_latency() {
  termios raw{};
  ::cfmakeraw(&raw);
  int master = -1, slave = -1;
  char name[256] = {};
  if (::openpty(&master, &slave, name, &raw, nullptr) != 0) {
    std::perror("posectl bench imu: openpty");
    return 1;
  }
  drivers::SerialSource source(drivers::SerialConfig{.path = name});
  std::string error;
  if (!source.open(error)) {
    std::fprintf(stderr, "posectl bench imu: %s\n", error.c_str());
    ::close(master);
    ::close(slave);
    return 1;
  }
  ::close(slave);

  // 1000 frames at 1 kHz; the counter indexes the write time.
  constexpr std::uint32_t kFrames = 1000;
  std::vector<std::int64_t> written_ns(kFrames, 0);
  std::vector<std::int64_t> latency_ns;
  latency_ns.reserve(kFrames);
  std::atomic<bool> write_ok{true};
  std::thread writer([&] {
    auto next = std::chrono::steady_clock::now();
    for (std::uint32_t i = 0; i < kFrames; ++i) {
      std::this_thread::sleep_until(next);
      const auto b = frame_bytes(i);
      written_ns[i] = drivers::host_now().ns;
      if (::write(master, b.data(), b.size()) != static_cast<ssize_t>(b.size())) write_ok = false;
      next += std::chrono::milliseconds(1);
    }
  });
  a9::A9Decoder decoder;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (latency_ns.size() < kFrames && std::chrono::steady_clock::now() < end) {
    drivers::RawChunk chunk;
    if (source.read(chunk, Duration::from_ms(50)) != drivers::ReadStatus::kData) continue;
    decoder.feed({reinterpret_cast<const std::uint8_t*>(chunk.bytes.data()), chunk.bytes.size()},
                 [&](const a9::A9Frame& f) {
                   const std::int64_t now = drivers::host_now().ns;
                   if (f.sensor.counter_us < kFrames) {
                     latency_ns.push_back(now - written_ns[f.sensor.counter_us]);
                   }
                 });
  }
  writer.join();
  ::close(master);
  if (!write_ok || latency_ns.size() != kFrames) {
    std::fprintf(stderr, "posectl bench imu: %zu of %u frames arrived\n", latency_ns.size(),
                 kFrames);
    return 1;
  }
  std::sort(latency_ns.begin(), latency_ns.end());
  report("imu", "serial_latency_p50", static_cast<double>(latency_ns[kFrames / 2]) * 1e-3, "us");
  report("imu", "serial_latency_p99", static_cast<double>(latency_ns[kFrames * 99 / 100]) * 1e-3,
         "us");
  return 0;
}

}  // namespace

int bench_imu() {
  const int a = bench_parser();
  const int b = bench_serial_latency();
  return a != 0 ? a : b;
}

}  // namespace posed::posectl
