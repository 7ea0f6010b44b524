// posectl bench velodyne: decoder throughput on one core (real VLP-32C packets when the shared
// data is found, else synthetic ones), and live UDP reception over loopback at 15,000 packets/s
// (5× a dual-return VLP-32C) while decoding and assembling scans, counting losses.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <memory>
#include <thread>
#include <vector>

#include "drivers/recording/mapped_file.hpp"
#include "drivers/recording/pcap_parser.hpp"
#include "drivers/recording/pcap_udp.hpp"
#include "drivers/velodyne/device_clock.hpp"
#include "drivers/velodyne/packet_decoder.hpp"
#include "drivers/velodyne/scan_assembler.hpp"
#include "drivers/velodyne/udp_source.hpp"
#include "tools/posectl/bench.hpp"

namespace posed::posectl {
namespace {

namespace vel = drivers::velodyne;
using Clock = std::chrono::steady_clock;

std::vector<std::vector<std::byte>> real_packets() {
  std::vector<std::filesystem::path> bases;
  if (const char* env = std::getenv("POSED_REALDATA")) bases.emplace_back(env);
  bases.push_back(std::filesystem::path(__FILE__).parent_path() / "../../../shared/realdata");
  std::vector<std::vector<std::byte>> out;
  for (const auto& base : bases) {
    const auto path = base / "velodyne_vlp32c/vlp32c_nebula_5scans.pcap";
    drivers::recording::MappedFile file;
    std::string error;
    if (!std::filesystem::exists(path) || !file.open(path.string(), error, "pcap")) continue;
    drivers::recording::PcapParser parser(file.bytes());
    if (parser.open() != drivers::recording::PcapStatus::kOk) continue;
    drivers::recording::PcapRecord rec;
    while (parser.next(rec) == drivers::recording::PcapStatus::kOk) {
      drivers::recording::UdpDatagram d;
      if (drivers::recording::extract_udp(rec.link_type, rec.frame, d) ==
          drivers::recording::FrameStatus::kOk) {
        out.emplace_back(d.payload.begin(), d.payload.end());
      }
    }
    if (!out.empty()) break;
  }
  return out;
}

/// A 10 Hz strongest-return VLP-32C turn, every channel returning (the worst case for decoding).
std::vector<std::vector<std::byte>> synthetic_packets() {
  std::vector<std::vector<std::byte>> out;
  for (std::uint32_t i = 0; i < 150; ++i) {
    std::vector<std::byte> p(vel::kDataPacketBytes, std::byte{0});
    for (std::uint32_t b = 0; b < 12; ++b) {
      std::byte* blk = p.data() + b * 100;
      blk[0] = std::byte{0xFF};
      blk[1] = std::byte{0xEE};
      const auto az = static_cast<std::uint16_t>((i * 240 + b * 20) % 36000);
      blk[2] = static_cast<std::byte>(az & 0xFF);
      blk[3] = static_cast<std::byte>(az >> 8);
      for (std::uint32_t c = 0; c < 32; ++c) {
        const auto d = static_cast<std::uint16_t>(1000 + (i * 31 + b * 7 + c * 13) % 5000);
        blk[4 + 3 * c] = static_cast<std::byte>(d & 0xFF);
        blk[5 + 3 * c] = static_cast<std::byte>(d >> 8);
        blk[6 + 3 * c] = static_cast<std::byte>(c);
      }
    }
    const std::uint32_t t = 1'000'000 + i * 664;
    for (int k = 0; k < 4; ++k)
      p[1200 + static_cast<std::size_t>(k)] = static_cast<std::byte>(t >> (8 * k));
    p[1204] = std::byte{0x37};
    p[1205] = std::byte{0x28};
    out.push_back(std::move(p));
  }
  return out;
}

double thread_cpu_s() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

/// Packets per second of this thread's CPU time: what one core achieves, even when the machine
/// is shared (wall-clock rates drop with other load; CPU time does not).
double decode_rate(const std::vector<std::vector<std::byte>>& packets, bool assemble) {
  vel::PacketDecoder decoder;
  PayloadPool pool(4, 240'000 * sizeof(LidarPoint));
  vel::ScanAssembler assembler(pool);
  vel::HourUnwrapper clock;
  auto out = std::make_unique<vel::DecodedPacket>();
  std::uint64_t n = 0, points = 0;
  const double t0 = thread_cpu_s();
  double s = 0;
  do {
    for (const auto& p : packets) {
      if (decoder.decode(p, *out) == vel::DecodeStatus::kOk) points += out->point_count;
      if (assemble) {
        assembler.add(*out, clock.unwrap(out->device_time_us));
        vel::AssembledScan scan;
        while (assembler.pop(scan)) points += scan.scan.point_count;
      }
      ++n;
    }
    s = thread_cpu_s() - t0;
  } while (s < 1.5);
  if (points == 0) return -1;
  return static_cast<double>(n) / s;
}

}  // namespace

int bench_velodyne() {
  auto packets = real_packets();
  const bool real = !packets.empty();
  if (!real) packets = synthetic_packets();
  const char* kind = real ? "real" : "synthetic";
  std::fprintf(stderr, "posectl bench velodyne: decoding %zu %s VLP-32C packets\n", packets.size(),
               kind);
  report("velodyne", real ? "decode_real_packets" : "decode_synthetic_packets",
         decode_rate(packets, false), "packets/cpu-s");
  report("velodyne", "decode_all_channels_returning", decode_rate(synthetic_packets(), false),
         "packets/cpu-s");
  report("velodyne", "decode_and_assemble", decode_rate(packets, true), "packets/cpu-s");

  // Live: loopback sender at 15,000 packets/s for 2 s; the receiver decodes and assembles.
  vel::UdpSourceConfig cfg;
  cfg.sensor_address = "127.0.0.1";
  cfg.bind_address = "127.0.0.1";
  cfg.data_port = 0;
  cfg.position_port = 0;
  vel::UdpSource source(cfg);
  std::string error;
  if (!source.open(error)) {
    std::fprintf(stderr, "posectl bench velodyne: %s\n", error.c_str());
    return 1;
  }
  const std::uint16_t port = source.bound_port(0);
  constexpr std::uint64_t kRate = 15'000, kSeconds = 2, kTotal = kRate * kSeconds;
  std::atomic<bool> sender_done{false};
  std::thread sender([&] {
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    ::inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
    const auto t0 = Clock::now();
    for (std::uint64_t i = 0; i < kTotal; ++i) {
      // pace in 1 ms steps of 15 packets
      if (i % 15 == 0) {
        std::this_thread::sleep_until(t0 + std::chrono::microseconds(i * 1'000'000 / kRate));
      }
      const auto& p = packets[i % packets.size()];
      ::sendto(fd, p.data(), p.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
    }
    ::close(fd);
    sender_done = true;
  });
  vel::PacketDecoder decoder;
  PayloadPool pool(4, 240'000 * sizeof(LidarPoint));
  vel::ScanAssembler assembler(pool);
  vel::HourUnwrapper clock;
  auto out = std::make_unique<vel::DecodedPacket>();
  std::uint64_t received = 0;
  const auto t0 = Clock::now();
  auto quiet_since = Clock::now();
  while (received < kTotal) {
    drivers::RawChunk chunk;
    const auto st = source.read(chunk, Duration::from_ms(50));
    if (st == drivers::ReadStatus::kData) {
      ++received;
      quiet_since = Clock::now();
      if (decoder.decode(chunk.bytes, *out) == vel::DecodeStatus::kOk) {
        assembler.add(*out, clock.unwrap(out->device_time_us));
        vel::AssembledScan scan;
        while (assembler.pop(scan)) {
        }
      }
    } else if (sender_done && Clock::now() - quiet_since > std::chrono::milliseconds(300)) {
      break;
    }
  }
  const double s = std::chrono::duration<double>(Clock::now() - t0).count();
  sender.join();
  report("velodyne", "udp_sent", static_cast<double>(kTotal), "packets");
  report("velodyne", "udp_received", static_cast<double>(received), "packets");
  report("velodyne", "udp_lost", static_cast<double>(kTotal - received), "packets");
  report("velodyne", "udp_receive_rate", static_cast<double>(received) / s, "packets/s");
  report("velodyne", "udp_rcvbuf", static_cast<double>(source.stats().receive_buffer_bytes),
         "bytes");
  return received == kTotal ? 0 : 1;
}

}  // namespace posed::posectl
