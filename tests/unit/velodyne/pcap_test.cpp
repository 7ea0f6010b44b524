// pcap/pcapng reader: real captures, synthetic link types and byte orders, truncation anywhere.

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "drivers/recording/pcap_parser.hpp"
#include "drivers/recording/pcap_source.hpp"
#include "drivers/recording/pcap_udp.hpp"
#include "tests/common/realdata.hpp"

namespace posed::drivers::recording {
namespace {

struct Collected {
  std::vector<std::vector<std::byte>> payloads;
  std::vector<std::int64_t> stamps;
  std::vector<std::uint16_t> ports;
  PcapStatus end = PcapStatus::kOk;
  std::uint64_t end_offset = 0;
};

Collected collect(std::span<const std::byte> file) {
  Collected c;
  PcapParser parser(file);
  c.end = parser.open();
  if (c.end != PcapStatus::kOk) return c;
  PcapRecord rec;
  while ((c.end = parser.next(rec)) == PcapStatus::kOk) {
    UdpDatagram d;
    if (extract_udp(rec.link_type, rec.frame, d) != FrameStatus::kOk) continue;
    c.payloads.emplace_back(d.payload.begin(), d.payload.end());
    c.stamps.push_back(rec.timestamp_ns);
    c.ports.push_back(d.dst_port);
  }
  c.end_offset = parser.offset();
  return c;
}

void put16(std::vector<std::byte>& v, std::uint16_t x, bool big = false) {
  if (big) x = static_cast<std::uint16_t>((x >> 8) | (x << 8));
  v.push_back(static_cast<std::byte>(x & 0xFF));
  v.push_back(static_cast<std::byte>(x >> 8));
}
void put32(std::vector<std::byte>& v, std::uint32_t x, bool big = false) {
  if (big) x = __builtin_bswap32(x);
  for (int i = 0; i < 4; ++i) v.push_back(static_cast<std::byte>((x >> (8 * i)) & 0xFF));
}
void put_be16(std::vector<std::byte>& v, std::uint16_t x) {
  v.push_back(static_cast<std::byte>(x >> 8));
  v.push_back(static_cast<std::byte>(x & 0xFF));
}

/// An IPv4/UDP packet (no link header) carrying `payload` to `port`.
std::vector<std::byte> ipv4_udp(std::span<const std::byte> payload, std::uint16_t port) {
  std::vector<std::byte> v;
  const auto total = static_cast<std::uint16_t>(20 + 8 + payload.size());
  v.push_back(std::byte{0x45});
  v.push_back(std::byte{0});
  put_be16(v, total);
  put_be16(v, 0);
  put_be16(v, 0x4000);  // DF
  v.push_back(std::byte{64});
  v.push_back(std::byte{17});
  put_be16(v, 0);
  for (int b : {192, 168, 1, 201, 255, 255, 255, 255}) v.push_back(static_cast<std::byte>(b));
  put_be16(v, port);
  put_be16(v, port);
  put_be16(v, static_cast<std::uint16_t>(8 + payload.size()));
  put_be16(v, 0);
  v.insert(v.end(), payload.begin(), payload.end());
  return v;
}

std::vector<std::byte> with_link(std::uint32_t link, std::vector<std::byte> ip) {
  std::vector<std::byte> f;
  if (link == linktype::kEthernet) {
    f.resize(12, std::byte{0xAA});
    put_be16(f, 0x8100);  // one VLAN tag
    put_be16(f, 0x0005);
    put_be16(f, 0x0800);
  } else if (link == linktype::kLinuxSll) {
    f.resize(14, std::byte{0});
    put_be16(f, 0x0800);
  } else if (link == linktype::kLinuxSll2) {
    put_be16(f, 0x0800);
    f.resize(20, std::byte{0});
  }
  f.insert(f.end(), ip.begin(), ip.end());
  return f;
}

std::vector<std::byte> classic_pcap(std::uint32_t link, bool big, bool nanos,
                                    const std::vector<std::vector<std::byte>>& frames,
                                    std::int64_t t0_ns) {
  std::vector<std::byte> f;
  put32(f, nanos ? 0xA1B23C4D : 0xA1B2C3D4, big);
  put16(f, 2, big);
  put16(f, 4, big);
  put32(f, 0, big);
  put32(f, 0, big);
  put32(f, 65535, big);
  put32(f, link, big);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const std::int64_t t = t0_ns + static_cast<std::int64_t>(i) * 663'552;
    put32(f, static_cast<std::uint32_t>(t / 1'000'000'000), big);
    put32(f, static_cast<std::uint32_t>(nanos ? t % 1'000'000'000 : (t % 1'000'000'000) / 1000),
          big);
    put32(f, static_cast<std::uint32_t>(frames[i].size()), big);
    put32(f, static_cast<std::uint32_t>(frames[i].size()), big);
    f.insert(f.end(), frames[i].begin(), frames[i].end());
  }
  return f;
}

std::vector<std::byte> pcapng(std::uint32_t link, const std::vector<std::vector<std::byte>>& frames,
                              std::int64_t t0_ns, bool big) {
  std::vector<std::byte> f;
  // Section header
  put32(f, 0x0A0D0D0A, big);
  put32(f, 28, big);
  put32(f, 0x1A2B3C4D, big);
  put16(f, 1, big);
  put16(f, 0, big);
  put32(f, 0xFFFFFFFF, big);
  put32(f, 0xFFFFFFFF, big);
  put32(f, 28, big);
  // Interface with if_tsresol = 9 (nanoseconds)
  put32(f, 1, big);
  put32(f, 32, big);
  put16(f, static_cast<std::uint16_t>(link), big);
  put16(f, 0, big);
  put32(f, 0, big);
  put16(f, 9, big);
  put16(f, 1, big);
  f.push_back(std::byte{9});
  f.resize(f.size() + 3, std::byte{0});
  put32(f, 0, big);  // opt_endofopt
  put32(f, 32, big);
  // A name-resolution block the reader must skip
  put32(f, 4, big);
  put32(f, 16, big);
  put32(f, 0, big);
  put32(f, 16, big);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto& fr = frames[i];
    const std::uint32_t padded = static_cast<std::uint32_t>((fr.size() + 3) & ~std::size_t{3});
    const std::uint32_t len = 32 + padded;
    const auto t = static_cast<std::uint64_t>(t0_ns + static_cast<std::int64_t>(i) * 663'552);
    put32(f, 6, big);
    put32(f, len, big);
    put32(f, 0, big);
    put32(f, static_cast<std::uint32_t>(t >> 32), big);
    put32(f, static_cast<std::uint32_t>(t & 0xFFFFFFFF), big);
    put32(f, static_cast<std::uint32_t>(fr.size()), big);
    put32(f, static_cast<std::uint32_t>(fr.size()), big);
    f.insert(f.end(), fr.begin(), fr.end());
    f.resize(f.size() + (padded - fr.size()), std::byte{0});
    put32(f, len, big);
  }
  return f;
}

std::vector<std::vector<std::byte>> sample_payloads() {
  std::vector<std::vector<std::byte>> p;
  for (int i = 0; i < 5; ++i) {
    std::vector<std::byte> v(i == 4 ? 512 : 1206);
    for (std::size_t k = 0; k < v.size(); ++k)
      v[k] = static_cast<std::byte>((k * 7 + static_cast<std::size_t>(i)) & 0xFF);
    p.push_back(std::move(v));
  }
  return p;
}

TEST(Pcap, RealVlp32cCapture) {
  POSED_REQUIRE_REALDATA(path, "velodyne_vlp32c/vlp32c_nebula_5scans.pcap");
  const auto bytes = test::read_std_bytes(path);
  const Collected c = collect(bytes);
  EXPECT_EQ(c.end, PcapStatus::kEnd);
  EXPECT_EQ(c.end_offset, bytes.size());
  ASSERT_EQ(c.payloads.size(), 379u);
  for (std::size_t i = 0; i < c.payloads.size(); ++i) {
    EXPECT_EQ(c.payloads[i].size(), 1206u);
    EXPECT_EQ(c.ports[i], 2368);
  }
  EXPECT_EQ(c.stamps.front(), 1713492677LL * 1'000'000'000 + 327'771'000);
}

TEST(Pcap, RealHdl32eCaptureHasDataAndPositionPackets) {
  POSED_REQUIRE_REALDATA(path, "velodyne_hdl32e/monterey-first-100-packets.pcap");
  const auto bytes = test::read_std_bytes(path);
  const Collected c = collect(bytes);
  EXPECT_EQ(c.end, PcapStatus::kEnd);
  std::size_t data = 0, position = 0;
  for (std::size_t i = 0; i < c.payloads.size(); ++i) {
    if (c.ports[i] == 2368 && c.payloads[i].size() == 1206) ++data;
    if (c.ports[i] == 8308 && c.payloads[i].size() == 512) ++position;
  }
  EXPECT_EQ(data, 2702u);
  EXPECT_EQ(position, 299u);
}

TEST(Pcap, TruncatedAnywhereReportsTheOffsetAndNeverOverreads) {
  POSED_REQUIRE_REALDATA(path, "velodyne_vlp32c/vlp32c_nebula_5scans.pcap");
  const auto bytes = test::read_std_bytes(path);
  // Record k starts at 24 + k * (16 + 1248).
  for (std::size_t cut :
       {std::size_t{0}, std::size_t{3}, std::size_t{23}, std::size_t{24 + 10},
        std::size_t{24 + 16 + 500}, std::size_t{24 + 1264 * 7 + 1000}, bytes.size() - 1}) {
    // A heap copy of exactly `cut` bytes lets ASan catch any read past the end.
    std::vector<std::byte> part(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(cut));
    const Collected c = collect(part);
    EXPECT_EQ(c.end, PcapStatus::kTruncated) << "cut at " << cut;
    if (cut >= 24) {
      const std::size_t whole = (cut - 24) / 1264;
      EXPECT_EQ(c.payloads.size(), whole) << "cut at " << cut;
      EXPECT_EQ(c.end_offset, 24 + whole * 1264) << "cut at " << cut;
    }
  }
  PcapParser p(std::span<const std::byte>(bytes.data(), 24 + 1264 * 2 + 30));
  ASSERT_EQ(p.open(), PcapStatus::kOk);
  PcapRecord rec;
  EXPECT_EQ(p.next(rec), PcapStatus::kOk);
  EXPECT_EQ(p.next(rec), PcapStatus::kOk);
  EXPECT_EQ(p.next(rec), PcapStatus::kTruncated);
  EXPECT_EQ(p.next(rec), PcapStatus::kTruncated);  // sticky
  EXPECT_NE(p.describe_error().find("offset 2552"), std::string::npos) << p.describe_error();
}

TEST(Pcap, LinkTypesByteOrdersAndResolutions) {
  const auto payloads = sample_payloads();
  const std::int64_t t0 = 1'700'000'000'123'456'789;
  for (std::uint32_t link : {linktype::kEthernet, linktype::kLinuxSll, linktype::kLinuxSll2,
                             linktype::kRaw, linktype::kIpv4}) {
    std::vector<std::vector<std::byte>> frames;
    for (std::size_t i = 0; i < payloads.size(); ++i) {
      frames.push_back(with_link(link, ipv4_udp(payloads[i], i == 4 ? 8308 : 2368)));
    }
    for (bool big : {false, true}) {
      for (int variant = 0; variant < 3; ++variant) {
        SCOPED_TRACE("link " + std::to_string(link) + (big ? " big-endian" : " little-endian") +
                     " variant " + std::to_string(variant));
        const auto file = variant == 2 ? pcapng(link, frames, t0, big)
                                       : classic_pcap(link, big, variant == 1, frames, t0);
        const Collected c = collect(file);
        EXPECT_EQ(c.end, PcapStatus::kEnd);
        ASSERT_EQ(c.payloads.size(), payloads.size());
        for (std::size_t i = 0; i < payloads.size(); ++i) {
          EXPECT_EQ(c.payloads[i], payloads[i]);
          EXPECT_EQ(c.ports[i], i == 4 ? 8308 : 2368);
          const std::int64_t want = t0 + static_cast<std::int64_t>(i) * 663'552;
          // microsecond pcap rounds down to µs; ns pcap and pcapng (tsresol 9) are exact
          EXPECT_EQ(c.stamps[i], variant == 0 ? want / 1000 * 1000 : want);
        }
      }
    }
  }
}

TEST(Pcap, BadMagicAndBadBlocks) {
  std::vector<std::byte> junk(64, std::byte{0x42});
  PcapParser p(junk);
  EXPECT_EQ(p.open(), PcapStatus::kBadMagic);
  auto file = pcapng(linktype::kRaw, {ipv4_udp(sample_payloads()[0], 2368)}, 0, false);
  file[28 + 32 + 16 + 4] = std::byte{0x13};  // EPB length no longer a multiple of 4
  const Collected c = collect(file);
  EXPECT_EQ(c.end, PcapStatus::kBadBlock);
  EXPECT_EQ(c.end_offset, 28u + 32u + 16u);
}

TEST(PcapUdp, NonUdpFragmentsAndSnaplenCuts) {
  const auto payload = sample_payloads()[0];
  auto ip = ipv4_udp(payload, 2368);
  UdpDatagram d;
  EXPECT_EQ(extract_udp(linktype::kRaw, ip, d), FrameStatus::kOk);
  auto tcp = ip;
  tcp[9] = std::byte{6};
  EXPECT_EQ(extract_udp(linktype::kRaw, tcp, d), FrameStatus::kNotUdp);
  auto frag = ip;
  frag[6] = std::byte{0x20};  // more fragments
  EXPECT_EQ(extract_udp(linktype::kRaw, frag, d), FrameStatus::kFragment);
  EXPECT_EQ(extract_udp(linktype::kRaw, std::span(ip).first(600), d), FrameStatus::kTruncated);
  EXPECT_EQ(extract_udp(999, ip, d), FrameStatus::kUnsupportedLink);
  std::vector<std::byte> arp(60, std::byte{0});
  arp[12] = std::byte{0x08};
  arp[13] = std::byte{0x06};
  EXPECT_EQ(extract_udp(linktype::kEthernet, arp, d), FrameStatus::kNotIp);
  auto bad_len = ip;
  bad_len[20 + 4] = std::byte{0xFF};  // UDP length beyond the IP packet
  EXPECT_EQ(extract_udp(linktype::kRaw, bad_len, d), FrameStatus::kMalformed);
}

TEST(PcapSource, AsFastAsPossibleThenEndOfStream) {
  POSED_REQUIRE_REALDATA(path, "velodyne_hdl32e/monterey-first-100-packets.pcap");
  PcapSource source({.path = path, .name = "lidar", .ports = {2368, 8308}, .speed = 0.0});
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  std::size_t per_channel[2] = {0, 0};
  RawChunk chunk;
  ReadStatus s;
  while ((s = source.read(chunk, Duration::from_ms(10))) == ReadStatus::kData) {
    ASSERT_LT(chunk.channel, 2u);
    ++per_channel[chunk.channel];
    EXPECT_EQ(chunk.bytes.size(), chunk.channel == 0 ? 1206u : 512u);
  }
  EXPECT_EQ(s, ReadStatus::kEndOfStream);
  EXPECT_EQ(per_channel[0], 2702u);
  EXPECT_EQ(per_channel[1], 299u);
  EXPECT_EQ(source.counters().chunks, 3001u);
  EXPECT_TRUE(source.file_error().empty());
}

TEST(PcapSource, OriginalTimingIsPacedAndTruncationIsReported) {
  POSED_REQUIRE_REALDATA(path, "velodyne_hdl32e/monterey-first-100-packets.pcap");
  const auto bytes = test::read_std_bytes(path);
  // The first 40 records plus half of one: the capture spans ~22 ms before the cut.
  const auto tmp = std::filesystem::temp_directory_path() /
                   ("posed_pcap_trunc_" + std::to_string(::getpid()) + ".pcap");
  {
    std::ofstream out(tmp, std::ios::binary);
    std::size_t off = 24;
    for (int i = 0; i < 40; ++i) {
      std::uint32_t incl = 0;
      std::memcpy(&incl, bytes.data() + off + 8, 4);
      off += 16 + incl;
    }
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(off + 100));
  }
  PcapSource source({.path = tmp.string(), .name = "lidar", .ports = {2368, 8308}, .speed = 1.0});
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;
  RawChunk chunk;
  std::vector<std::int64_t> capture_ns;
  const auto t0 = std::chrono::steady_clock::now();
  ReadStatus s;
  while ((s = source.read(chunk, Duration::from_ms(50))) != ReadStatus::kEndOfStream) {
    if (s == ReadStatus::kData) capture_ns.push_back(chunk.host_receive.ns);
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::filesystem::remove(tmp);
  ASSERT_EQ(capture_ns.size(), 40u);
  const double span_s = static_cast<double>(capture_ns.back() - capture_ns.front()) * 1e-9;
  EXPECT_GE(elapsed_s, span_s * 0.9) << "replay ran faster than the capture";
  EXPECT_NE(source.file_error().find("truncated record at offset"), std::string::npos)
      << source.file_error();
}

TEST(PcapSource, StopEndsTheStreamAndMissingFileFails) {
  PcapSource missing({.path = "/nonexistent/x.pcap"});
  std::string error;
  EXPECT_FALSE(missing.open(error));
  EXPECT_NE(error.find("/nonexistent/x.pcap"), std::string::npos) << error;
  POSED_REQUIRE_REALDATA(path, "velodyne_vlp32c/vlp32c_nebula_5scans.pcap");
  PcapSource source({.path = path, .speed = 1.0});
  ASSERT_TRUE(source.open(error)) << error;
  source.request_stop();
  RawChunk chunk;
  EXPECT_EQ(source.read(chunk, Duration::from_ms(10)), ReadStatus::kEndOfStream);
}

}  // namespace
}  // namespace posed::drivers::recording
