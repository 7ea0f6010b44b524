// Scan assembly: real capture (front half of each turn only), and synthetic rotations with
// packet loss, dual returns, pool exhaustion and clock jumps.

#include "drivers/velodyne/scan_assembler.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <set>

#include "drivers/velodyne/calibration_loader.hpp"
#include "drivers/velodyne/device_clock.hpp"
#include "tests/common/realdata.hpp"
#include "tests/unit/velodyne/capture_fixture.hpp"
#include "tests/unit/velodyne/packet_builder.hpp"

namespace posed::drivers::velodyne {
namespace {

constexpr std::size_t kScanBytes = 130'000 * sizeof(LidarPoint);

struct Assembly {
  std::vector<AssembledScan> scans;
  std::uint64_t decoded_points = 0;
  ScanAssemblerCounters counters;
};

Assembly assemble(const std::vector<std::vector<std::byte>>& packets, std::uint32_t cut_cdeg,
                  PayloadPool& pool, bool pop_each = true) {
  Assembly run;
  PacketDecoder decoder;
  ScanAssembler assembler(pool, {.cut_azimuth_cdeg = cut_cdeg});
  HourUnwrapper clock;
  auto out = std::make_unique<DecodedPacket>();
  AssembledScan scan;
  for (const auto& p : packets) {
    if (decoder.decode(p, *out) != DecodeStatus::kOk) continue;
    run.decoded_points += out->point_count;
    assembler.add(*out, clock.unwrap(out->device_time_us));
    while (pop_each && assembler.pop(scan)) run.scans.push_back(std::move(scan));
  }
  assembler.flush();
  while (assembler.pop(scan)) run.scans.push_back(std::move(scan));
  run.counters = assembler.counters();
  return run;
}

void expect_consistent(const Assembly& run) {
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    const auto& s = run.scans[i];
    SCOPED_TRACE("scan " + std::to_string(i));
    total += s.scan.point_count;
    const auto points = s.scan.points.as<LidarPoint>();
    ASSERT_LE(s.scan.point_count, points.size());
    const std::int64_t duration = s.info.device_end.ns - s.info.device_start.ns;
    std::int32_t prev = 0, latest = 0;
    for (std::uint32_t k = 0; k < s.scan.point_count; ++k) {
      EXPECT_GE(points[k].offset_ns, 0);
      EXPECT_LE(points[k].offset_ns, duration);
      // firing order; in dual mode a firing's second block restarts at the firing's start
      EXPECT_GE(points[k].offset_ns, prev - 55'296) << "points are in firing order";
      prev = points[k].offset_ns;
      latest = std::max(latest, prev);
    }
    if (s.scan.point_count > 0) {
      EXPECT_EQ(latest, duration) << "end stamp = the latest point's firing";
    }
    EXPECT_EQ(s.scan.end_stamp.ns - s.scan.start_stamp.ns, duration);
    EXPECT_EQ(s.scan.sequence, i);
  }
  EXPECT_EQ(total, run.decoded_points) << "every point in exactly one scan";
}

TEST(ScanAssembler, RealCaptureCutBehindTheSensor) {
  POSED_REQUIRE_REALDATA(pcap, "velodyne_vlp32c/vlp32c_nebula_5scans.pcap");
  std::vector<std::vector<std::byte>> packets;
  for (auto& d : test::load_datagrams(pcap)) packets.push_back(std::move(d.payload));
  PayloadPool pool(8, kScanBytes);
  // Cut at 180° (behind): each kept front half (270°→90°) is one scan. The recorder spliced
  // each turn's last packet: its first blocks are at ~90°, its last blocks already at 270° of the
  // next kept half (50 ms later, under the same packet stamp). So the cut falls inside those
  // packets, and the last packet of the file adds a sixth, tiny scan.
  const Assembly run = assemble(packets, 18000, pool);
  ASSERT_EQ(run.scans.size(), 6u);
  expect_consistent(run);
  EXPECT_EQ(run.decoded_points, 131305u);
  EXPECT_FALSE(run.scans[0].info.starts_at_cut);
  for (std::size_t i = 1; i < 6; ++i) EXPECT_TRUE(run.scans[i].info.starts_at_cut);
  for (std::size_t i = 1; i < 5; ++i) {
    // the rear half was not recorded: 50.375 ms of device time = 75 packets missing
    EXPECT_EQ(run.scans[i].info.missing_packets, 75u);
  }
  EXPECT_EQ(run.counters.gaps, 4u);
  EXPECT_EQ(run.counters.missing_packets, 300u);
  std::uint32_t packets_in_scans = 0;
  for (std::size_t i = 0; i < 5; ++i) {
    const auto& s = run.scans[i];
    // a front half is ~76 packets × 12 firings × 32 lasers, ~26k returns here
    EXPECT_GT(s.scan.point_count, 25'000u);
    std::set<std::uint16_t> rings;
    const auto points = s.scan.points.as<LidarPoint>();
    for (std::uint32_t k = 0; k < s.scan.point_count; ++k) rings.insert(points[k].ring);
    EXPECT_EQ(rings.size(), 32u);
    const double duration_s = (s.info.device_end - s.info.device_start).seconds();
    // 180° at 10 Hz is 50 ms; the spliced blocks carry a stamp 50 ms early, so up to 100 ms
    EXPECT_GT(duration_s, 0.045);
    EXPECT_LT(duration_s, 0.101);
  }
  for (const auto& s : run.scans) packets_in_scans += s.info.packets;
  EXPECT_EQ(run.scans[5].info.packets, 1u);
  EXPECT_LT(run.scans[5].scan.point_count, 384u);
  // spliced packets contribute to two scans
  EXPECT_EQ(packets_in_scans, 379u + 5u);
}

TEST(ScanAssembler, RealCaptureCutInFront) {
  POSED_REQUIRE_REALDATA(pcap, "velodyne_vlp32c/vlp32c_nebula_5scans.pcap");
  std::vector<std::vector<std::byte>> packets;
  for (auto& d : test::load_datagrams(pcap)) packets.push_back(std::move(d.payload));
  PayloadPool pool(8, kScanBytes);
  // Cut at 0°: each scan is 0°→90° of one turn and 270°→360° of the next (with the gap).
  const Assembly run = assemble(packets, 0, pool);
  ASSERT_EQ(run.scans.size(), 6u);
  expect_consistent(run);
  for (std::size_t i = 1; i + 1 < run.scans.size(); ++i) {
    EXPECT_TRUE(run.scans[i].info.starts_at_cut);
    EXPECT_TRUE(run.scans[i].info.ends_at_cut);
    EXPECT_FALSE(run.scans[i].info.complete()) << "the rear half is missing";
    EXPECT_NEAR((run.scans[i].info.device_end - run.scans[i].info.device_start).seconds(), 0.1,
                0.006);
  }
}

std::vector<std::vector<std::byte>> rotation(std::uint32_t packets, std::uint8_t mode,
                                             std::uint32_t start_az = 35000) {
  // 10 Hz: 0.2° per 55.296 µs firing; single 12 firings, dual 6 firings per packet.
  const bool dual = mode == 0x39;
  const std::uint32_t firings = dual ? 6 : 12;
  const double period_us = firings * 55.296;
  std::vector<std::vector<std::byte>> out;
  for (std::uint32_t i = 0; i < packets; ++i) {
    test::PacketSpec s;
    s.mode = mode;
    s.azimuth_cdeg = (start_az + i * firings * 20) % 36000;
    s.time_us = static_cast<std::uint32_t>(1'000'000 + i * period_us);
    if (dual) {
      // odd blocks (strongest) differ from the last return on even channels only
      s.distance = [](std::uint32_t b, std::uint32_t c) -> std::uint16_t {
        return (b % 2 == 1 && c % 2 == 0) ? 1000 : 2500;
      };
    }
    out.push_back(test::make_packet(s));
  }
  return out;
}

TEST(ScanAssembler, SyntheticFullTurnsAndPacketLoss) {
  PayloadPool pool(8, kScanBytes);
  auto packets = rotation(400, 0x37);  // 150 packets per turn: partial, 2 full, partial
  Assembly run = assemble(packets, 0, pool);
  ASSERT_EQ(run.scans.size(), 4u);
  expect_consistent(run);
  EXPECT_TRUE(run.scans[1].info.complete());
  EXPECT_TRUE(run.scans[2].info.complete());
  EXPECT_EQ(run.scans[1].scan.point_count, 1800u * 32u);  // 1800 firings per turn
  EXPECT_FALSE(run.scans[0].info.complete());
  EXPECT_FALSE(run.scans[3].info.complete());

  // Lose three packets inside the second turn.
  packets.erase(packets.begin() + 200, packets.begin() + 203);
  run = assemble(packets, 0, pool);
  ASSERT_EQ(run.scans.size(), 4u);
  expect_consistent(run);
  EXPECT_TRUE(run.scans[1].info.complete());
  EXPECT_EQ(run.scans[2].info.missing_packets, 3u);
  EXPECT_FALSE(run.scans[2].info.complete());
  EXPECT_EQ(run.counters.missing_packets, 3u);
}

TEST(ScanAssembler, OutageLongerThanATurnStillCuts) {
  PayloadPool pool(8, kScanBytes);
  auto packets = rotation(600, 0x37, 1000);
  // Keep 0..99 and 260.. : 160 packets (1.07 turns) lost, the azimuth seems to advance little.
  packets.erase(packets.begin() + 100, packets.begin() + 260);
  const Assembly run = assemble(packets, 0, pool);
  expect_consistent(run);
  // Without the time check, the scan open before the outage would swallow the turn after it.
  for (const auto& s : run.scans) {
    EXPECT_LT((s.info.device_end - s.info.device_start).seconds(), 0.1 + 1e-3);
  }
}

TEST(ScanAssembler, ARepeatedPacketIsLeftOutInsteadOfCuttingTheScan) {
  // A duplicated datagram (or a late one, stamped with the newest device time): its firings
  // would run backwards through the open scan and cut it at every repeat.
  PayloadPool pool(8, kScanBytes);
  auto packets = rotation(400, 0x37);
  const Assembly clean = assemble(packets, 0, pool);
  std::vector<std::vector<std::byte>> doubled;
  for (std::size_t i = 0; i < packets.size(); ++i) {
    doubled.push_back(packets[i]);
    if (i >= 100 && i < 250) doubled.push_back(packets[i]);  // every packet of a turn twice
  }
  const Assembly run = assemble(doubled, 0, pool);
  ASSERT_EQ(run.scans.size(), clean.scans.size());
  EXPECT_EQ(run.counters.repeated_packets, 150u);
  for (std::size_t i = 0; i < run.scans.size(); ++i) {
    EXPECT_EQ(run.scans[i].scan.point_count, clean.scans[i].scan.point_count) << "scan " << i;
    EXPECT_EQ(run.scans[i].info.complete(), clean.scans[i].info.complete()) << "scan " << i;
  }
}

TEST(ScanAssembler, DualReturns) {
  PayloadPool pool(8, 2 * kScanBytes);
  const auto packets = rotation(700, 0x39);  // 300 packets per turn in dual mode
  const Assembly run = assemble(packets, 0, pool);
  expect_consistent(run);
  ASSERT_GE(run.scans.size(), 3u);
  const auto& full = run.scans[1];
  EXPECT_TRUE(full.info.complete());
  // 1800 firings × 32 last returns + 16 differing strongest returns each
  EXPECT_EQ(full.scan.point_count, 1800u * 48u);
  const auto points = full.scan.points.as<LidarPoint>();
  std::uint32_t second = 0;
  for (std::uint32_t k = 0; k < full.scan.point_count; ++k) second += points[k].return_index;
  EXPECT_EQ(second, 1800u * 16u);
}

TEST(ScanAssembler, PoolExhaustionDropsScansButKeepsSequence) {
  PayloadPool pool(1, kScanBytes);
  const auto packets = rotation(400, 0x37);
  const Assembly run = assemble(packets, 0, pool, /*pop_each=*/false);
  // One buffer: the first scan holds it until popped at the end; the others find none.
  EXPECT_EQ(run.counters.scans_no_buffer, 3u);
  ASSERT_EQ(run.scans.size(), 1u);
  EXPECT_EQ(run.scans[0].scan.sequence, 0u);
}

TEST(ScanAssembler, SmallBufferCountsOverflow) {
  PayloadPool pool(8, 1000 * sizeof(LidarPoint));
  const auto packets = rotation(160, 0x37);
  const Assembly run = assemble(packets, 0, pool);
  for (const auto& s : run.scans) EXPECT_LE(s.scan.point_count, 1000u);
  EXPECT_GT(run.counters.points_overflow, 0u);
}

TEST(ScanAssembler, ClockJumpBackwardsClosesTheScan) {
  PayloadPool pool(8, kScanBytes);
  auto packets = rotation(50, 0x37);
  auto again = rotation(50, 0x37);  // same stamps again: the sensor restarted
  packets.insert(packets.end(), again.begin(), again.end());
  PacketDecoder decoder;
  ScanAssembler assembler(pool, {.cut_azimuth_cdeg = 0});
  auto out = std::make_unique<DecodedPacket>();
  for (const auto& p : packets) {
    ASSERT_EQ(decoder.decode(p, *out), DecodeStatus::kOk);
    assembler.add(*out, DeviceTime::from_ns(std::int64_t{out->device_time_us} * 1000));
  }
  assembler.flush();
  EXPECT_EQ(assembler.counters().time_jumps, 1u);
  AssembledScan s;
  int scans = 0;
  while (assembler.pop(s)) ++scans;
  EXPECT_GE(scans, 2);
}

TEST(HourUnwrapper, CountsWrapsAndToleratesStragglers) {
  HourUnwrapper u;
  EXPECT_EQ(u.unwrap(3'599'999'000).ns, 3'599'999'000'000);
  EXPECT_EQ(u.unwrap(500).ns, 3'600'000'500'000);
  EXPECT_EQ(u.unwrap(3'599'999'500).ns, 3'599'999'500'000);  // late packet of the old hour
  EXPECT_EQ(u.unwrap(1000).ns, 3'600'001'000'000);
}

}  // namespace
}  // namespace posed::drivers::velodyne
