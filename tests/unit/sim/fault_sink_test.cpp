// Faults laid over a simulated run (posectl sim --fault): each kind does what it says to the
// streams it names, inside its window only, and leaves the rest byte for byte.

#include "tools/sim/fault_sink.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace posed::sim {
namespace {

constexpr std::int64_t kEpochNs = 100'000'000'000;

HostTime at(double t_s) {
  return HostTime::from_ns(kEpochNs + static_cast<std::int64_t>(t_s * 1e9));
}

std::vector<std::byte> bytes_of(std::size_t n, int seed) {
  std::vector<std::byte> b(n);
  for (std::size_t i = 0; i < n; ++i) b[i] = static_cast<std::byte>((i * 31 + seed * 7) & 0xFF);
  return b;
}

/// The rig's streams into a FaultSink over a MemorySink, then 10 messages a second per stream
/// for 4 s (message k of a stream at k * 0.1 s, bytes that differ per message).
struct FaultedRun {
  MemorySink memory;
  FaultSink sink;
  int imu, lidar, position, visible, thermal;
  explicit FaultedRun(std::vector<Fault> faults)
      : sink(memory, std::move(faults), kEpochNs, 42),
        imu(sink.add_stream({"imu", "a9-serial", 0, {}})),
        lidar(sink.add_stream({"lidar", "velodyne-udp-data", 0, {}})),
        position(sink.add_stream({"lidar", "velodyne-udp-position", 1, {}})),
        visible(sink.add_stream({"visible", "yuyv", 0, {}})),
        thermal(sink.add_stream({"thermal", "y8", 0, {}})) {
    for (int k = 0; k < 40; ++k) {
      for (const int s : {imu, lidar, position, visible, thermal}) {
        EXPECT_TRUE(sink.write_raw(s, at(k * 0.1), bytes_of(64, k * 10 + s)));
      }
    }
    EXPECT_TRUE(sink.finish());
  }
  std::vector<MemorySink::Message> of(int stream) const {
    std::vector<MemorySink::Message> out;
    for (const auto& m : memory.messages) {
      if (m.stream == stream) out.push_back(m);
    }
    return out;
  }
};

TEST(FaultSink, ParsesKindStartAndDurationAndRefusesWhatItCannotRead) {
  Fault f;
  std::string error;
  ASSERT_TRUE(parse_fault("lidar_outage@30+5", f, error)) << error;
  EXPECT_EQ(f.kind, FaultKind::kLidarOutage);
  EXPECT_DOUBLE_EQ(f.start_s, 30);
  EXPECT_DOUBLE_EQ(f.duration_s, 5);
  EXPECT_EQ(to_string(f), "lidar_outage@30+5");
  ASSERT_TRUE(parse_fault("thermal_ffc@12.5+0.5", f, error)) << error;
  EXPECT_EQ(f.kind, FaultKind::kThermalFfc);
  EXPECT_FALSE(parse_fault("lidar_outage@30", f, error));
  EXPECT_NE(error.find("KIND@START+DURATION"), std::string::npos) << error;
  EXPECT_FALSE(parse_fault("tornado@1+2", f, error));
  EXPECT_NE(error.find("unknown kind 'tornado'"), std::string::npos) << error;
  EXPECT_NE(error.find("camera_blackout"), std::string::npos) << error;
  EXPECT_FALSE(parse_fault("imu_gap@1+0", f, error));
  EXPECT_FALSE(parse_fault("imu_gap@x+1", f, error));
}

TEST(FaultSink, AnOutageDropsOnlyItsStreamInsideTheWindow) {
  FaultedRun run({{FaultKind::kLidarOutage, 1.0, 1.5}});
  for (const int s : {run.lidar, run.position}) {
    const auto got = run.of(s);
    EXPECT_EQ(got.size(), 40u - 15u);
    for (const auto& m : got) {
      const double t = static_cast<double>(m.host_time.ns - kEpochNs) * 1e-9;
      EXPECT_FALSE(t >= 1.0 - 1e-9 && t < 2.5 - 1e-9) << t;
    }
  }
  EXPECT_EQ(run.of(run.imu).size(), 40u);
  EXPECT_EQ(run.of(run.visible).size(), 40u);
  EXPECT_EQ(run.sink.counts()[static_cast<std::size_t>(run.lidar)].dropped, 15u);
}

TEST(FaultSink, ABlackoutKeepsFramesComingBlackAndAFreezeRepeatsTheLastOne) {
  FaultedRun blackout({{FaultKind::kCameraBlackout, 1.0, 1.0}});
  const auto vis = blackout.of(blackout.visible);
  ASSERT_EQ(vis.size(), 40u);
  for (std::size_t k = 0; k < vis.size(); ++k) {
    const bool inside = k >= 10 && k < 20;
    const bool black = std::all_of(vis[k].bytes.begin(), vis[k].bytes.end(), [&](std::byte b) {
      return b == std::byte{16} || b == std::byte{128};
    });
    EXPECT_EQ(black, inside) << "frame " << k;
  }
  const auto th = blackout.of(blackout.thermal);
  EXPECT_TRUE(std::all_of(th[15].bytes.begin(), th[15].bytes.end(),
                          [&](std::byte b) { return b == th[15].bytes[0]; }));
  EXPECT_EQ(blackout.of(blackout.imu)[15].bytes, bytes_of(64, 150 + blackout.imu));

  FaultedRun ffc({{FaultKind::kThermalFfc, 1.0, 0.5}});
  const auto thermal = ffc.of(ffc.thermal);
  for (std::size_t k = 10; k < 15; ++k) EXPECT_EQ(thermal[k].bytes, thermal[9].bytes) << k;
  EXPECT_NE(thermal[15].bytes, thermal[9].bytes);
  EXPECT_EQ(ffc.of(ffc.visible)[12].bytes, bytes_of(64, 120 + ffc.visible)) << "thermal only";
  EXPECT_EQ(ffc.sink.counts()[static_cast<std::size_t>(ffc.thermal)].frozen, 5u);
}

TEST(FaultSink, CorruptionFlipsBytesInEveryStreamInsideTheWindowOnly) {
  FaultedRun run({{FaultKind::kCorruptBurst, 2.0, 0.5}});
  for (const int s : {run.imu, run.lidar, run.position, run.visible, run.thermal}) {
    const auto got = run.of(s);
    ASSERT_EQ(got.size(), 40u);
    for (std::size_t k = 0; k < got.size(); ++k) {
      const bool inside = k >= 20 && k < 25;
      EXPECT_EQ(got[k].bytes != bytes_of(64, static_cast<int>(k) * 10 + s), inside)
          << "stream " << s << " message " << k;
    }
  }
}

TEST(FaultSink, DuplicatesAndReordersKeepHostTimesInOrder) {
  FaultedRun dup({{FaultKind::kDuplicate, 0.0, 1.0}});
  EXPECT_EQ(dup.of(dup.imu).size(), 50u);
  FaultedRun reorder({{FaultKind::kReorder, 1.0, 1.0}});
  const auto got = reorder.of(reorder.imu);
  ASSERT_EQ(got.size(), 40u);
  EXPECT_EQ(got[10].bytes, bytes_of(64, 110 + reorder.imu));  // the later one first
  EXPECT_EQ(got[11].bytes, bytes_of(64, 100 + reorder.imu));
  for (std::size_t k = 1; k < reorder.memory.messages.size(); ++k) {
    EXPECT_GE(reorder.memory.messages[k].host_time.ns, reorder.memory.messages[k - 1].host_time.ns);
  }
}

}  // namespace
}  // namespace posed::sim
