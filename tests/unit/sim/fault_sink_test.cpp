// Faults laid over a simulated run (posectl sim --fault): each kind does what it says to the
// streams it names, inside its window only, and leaves the rest byte for byte.

#include "tools/sim/fault_sink.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "drivers/imu/a9_protocol.hpp"
#include "drivers/velodyne/packet_format.hpp"
#include "drivers/velodyne/position_packet.hpp"
#include "tools/sim/vlp32c_encoder.hpp"

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

namespace a9 = drivers::a9;
namespace vel = drivers::velodyne;

/// A9 sensor frames at 100 Hz for 3 s whose counter reads 4'000'000'000 µs + true time (it wraps
/// during the run), through a FaultSink; the counters of the frames that come out, by time.
std::vector<std::pair<double, std::uint32_t>> a9_counters_after(std::vector<Fault> faults) {
  MemorySink memory;
  FaultSink sink(memory, std::move(faults), kEpochNs, 1);
  const int imu = sink.add_stream({"imu", "a9-serial", 0, {}});
  std::vector<std::uint8_t> frame(a9::kSensorFrameSize);
  for (int k = 0; k < 300; ++k) {
    a9::A9SensorFrame f;
    f.counter_us = 4'000'000'000u + static_cast<std::uint32_t>(k) * 10'000u;
    EXPECT_EQ(a9::encode_a9_sensor_frame(f, frame), frame.size());
    const auto* b = reinterpret_cast<const std::byte*>(frame.data());
    EXPECT_TRUE(sink.write_raw(imu, at(k * 0.01), {b, frame.size()}));
  }
  std::vector<std::pair<double, std::uint32_t>> out;
  for (const auto& m : memory.messages) {
    a9::A9Decoder decoder;
    std::span<const std::uint8_t> input(reinterpret_cast<const std::uint8_t*>(m.bytes.data()),
                                        m.bytes.size());
    a9::A9Frame decoded;
    EXPECT_EQ(decoder.next(input, decoded), a9::DecodeStatus::kFrame) << "the CRC still holds";
    out.emplace_back(static_cast<double>(m.host_time.ns - kEpochNs) * 1e-9,
                     decoded.sensor.counter_us);
  }
  return out;
}

TEST(FaultSink, AnImuResetSilencesTheA9ThenRestartsItsCounterFromTheReboot) {
  const auto frames = a9_counters_after({{FaultKind::kImuReset, 1.0, 0.5}});
  ASSERT_EQ(frames.size(), 300u - 50u);
  for (const auto& [t, counter] : frames) {
    EXPECT_FALSE(t >= 1.0 - 1e-9 && t < 1.5 - 1e-9) << "rebooting at " << t;
    // Before: untouched. After: µs since the reboot at 1.0 s.
    const double expected_us = t < 1.0 ? 4e9 + t * 1e6 : (t - 1.0) * 1e6;
    EXPECT_NEAR(static_cast<double>(counter), expected_us, 1.0) << t;
  }
}

TEST(FaultSink, APpsLossLetsTheLidarClockRunFastThenStepBackAtTheRelock) {
  MemorySink memory;
  FaultSink sink(memory, {{FaultKind::kPpsLoss, 1.0, 2.0}}, kEpochNs, 1);
  const int data = sink.add_stream({"lidar", "velodyne-udp-data", 0, {}});
  const int position = sink.add_stream({"lidar", "velodyne-udp-position", 1, {}});
  const int imu = sink.add_stream({"imu", "a9-serial", 0, {}});
  // µs past the hour: 3599 s into the hour, so the free-running clock crosses the hour.
  const auto stamp_us = [](int k) {
    return 3'599'000'000u + static_cast<std::uint32_t>(k) * 1000u;
  };
  for (int k = 0; k < 4000; ++k) {
    std::vector<std::byte> packet(vel::kDataPacketBytes);
    for (std::size_t b = 0; b < 4; ++b) {
      packet[vel::kTimestampOffset + b] =
          static_cast<std::byte>(((stamp_us(k) % vel::kUsPerHour) >> (8 * b)) & 0xFF);
    }
    EXPECT_TRUE(sink.write_raw(data, at(k * 0.001), packet));
    if (k % 100 == 0) {
      std::vector<std::byte> pos(vel::kPositionPacketBytes);
      encode_position_packet(stamp_us(k) % vel::kUsPerHour, vel::PpsStatus::kLocked, "", pos);
      EXPECT_TRUE(sink.write_raw(position, at(k * 0.001), pos));
      EXPECT_TRUE(sink.write_raw(imu, at(k * 0.001), pos));
    }
  }
  std::size_t n_data = 0;
  for (const auto& m : memory.messages) {
    const double t = static_cast<double>(m.host_time.ns - kEpochNs) * 1e-9;
    const bool lost = t >= 1.0 - 1e-9 && t < 3.0 - 1e-9;
    if (m.stream == data) {
      std::uint32_t got = 0;
      for (std::size_t b = 0; b < 4; ++b) {
        got |= std::to_integer<std::uint32_t>(m.bytes[vel::kTimestampOffset + b]) << (8 * b);
      }
      const double truth_us = static_cast<double>(stamp_us(static_cast<int>(n_data++)));
      const double expected_us = lost ? truth_us + (t - 1.0) * kFreeRunPpm : truth_us;
      EXPECT_NEAR(static_cast<double>(got), std::fmod(expected_us, 3.6e9), 1.0) << t;
    } else {
      vel::PositionPacket parsed;
      vel::parse_position_packet(m.bytes, parsed);
      const bool says_absent = parsed.pps == vel::PpsStatus::kAbsent;
      EXPECT_EQ(says_absent, lost && m.stream == position) << "stream " << m.stream << " at " << t;
    }
  }
  EXPECT_EQ(n_data, 4000u);
  EXPECT_EQ(sink.counts()[static_cast<std::size_t>(data)].restamped, 2000u);
  EXPECT_EQ(sink.counts()[static_cast<std::size_t>(imu)].restamped, 0u);
}

}  // namespace
}  // namespace posed::sim
