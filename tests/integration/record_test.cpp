// posectl record as a user runs it: the synthetic A9 and a live UDP lidar fed by a sender in
// this test, recorded without decoding or fusion until SIGINT; the file is closed and indexed,
// holds exactly the bytes sent, carries the same channel metadata posed --record writes, and
// `posed --replay` takes it through the whole pipeline.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <random>
#include <thread>

#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/recorder.hpp"
#include "drivers/velodyne/calibration.hpp"
#include "tests/integration/hil_helpers.hpp"
#include "tests/integration/posed_process.hpp"
#include "tests/unit/velodyne/packet_builder.hpp"

namespace posed::testing {
namespace record_test {

using namespace std::chrono_literals;
using namespace hil_helpers;
namespace rec = drivers::recording;

/// Sends VLP-32C data packets (a spinning head at 600 rpm seeing a wall at 10 m) and a few
/// position packets from 127.0.0.1, as the sensor would, at about the sensor's rate.
struct LidarSender {
  std::vector<std::vector<std::byte>> data, position;

  void run(std::uint16_t data_port, std::uint16_t position_port, int packets) {
    const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    auto send_to = [&](std::uint16_t port, const std::vector<std::byte>& bytes) {
      sockaddr_in to{};
      to.sin_family = AF_INET;
      to.sin_port = htons(port);
      to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      ::sendto(fd, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    };
    for (int i = 0; i < packets; ++i) {
      test::PacketSpec spec;
      // 12 firings of 0.199 deg per packet at 1507 packets/s: 600 rpm.
      spec.azimuth_cdeg = static_cast<std::uint32_t>(i * 12 * 20) % 36000;
      spec.time_us = 1'000'000 + static_cast<std::uint32_t>(i * 663);
      data.push_back(test::make_packet(spec));
      send_to(data_port, data.back());
      if (i % 500 == 0) {
        std::vector<std::byte> p(512, std::byte{0});
        p[200] = static_cast<std::byte>(i & 0xFF);
        position.push_back(p);
        send_to(position_port, p);
      }
      // About 1500 packets/s, in bursts of 15 every 10 ms.
      if (i % 15 == 14) std::this_thread::sleep_for(10ms);
    }
    ::close(fd);
  }
};

/// Waits until `posectl record` says it records the IMU and the lidar: its sockets are open.
void wait_until_recording(PosedProcess& record) {
  const auto ready_by = std::chrono::steady_clock::now() + 20s;
  while (record.err().find("recording imu, lidar") == std::string::npos &&
         std::chrono::steady_clock::now() < ready_by) {
    ASSERT_FALSE(record.wait_for_exit(20ms).has_value()) << record.err();
  }
  ASSERT_NE(record.err().find("recording imu, lidar"), std::string::npos) << record.err();
}

std::string meta(const rec::McapChannelRecord& c, const std::string& key) {
  const auto it = c.metadata.find(key);
  return it == c.metadata.end() ? std::string() : it->second;
}

TEST(PosectlRecord, RecordsTheSourcesUntilSigintAndPosedReplaysTheFile) {
  TempDir dir;
  const std::uint16_t data_port = free_udp_port();
  const std::uint16_t position_port = free_udp_port();
  const std::string config =
      dir.write("posed.yaml", dds_config() +
                                  "imu:\n  source: synthetic\n"
                                  "synthetic_imu:\n  static_s: 1.5\n  ramp_s: 2\n"
                                  "lidar:\n  enabled: true\n  source: udp\n  address: 127.0.0.1\n"
                                  "  data_port: " +
                                  std::to_string(data_port) +
                                  "\n  position_port: " + std::to_string(position_port) + "\n" +
                                  "estimator:\n  init_static_s: 0.5\n");
  const std::string recording = dir.file("run.mcap");
  TempDir record_dir;
  PosedProcess record(
      {build_dir() + "/tools/posectl/posectl", "record", "-o", recording, "--config", config}, {},
      record_dir);
  ASSERT_NO_FATAL_FAILURE(wait_until_recording(record));

  LidarSender sender;
  sender.run(data_port, position_port, 4500);  // 3 s
  std::this_thread::sleep_for(500ms);          // the last datagrams reach the Recorder
  record.signal(SIGINT);
  ASSERT_EQ(record.wait_for_exit(30s), 0) << record.err();
  const std::string summary = record.out();
  EXPECT_NE(summary.find("stopped by          Interrupt"), std::string::npos) << summary;
  EXPECT_EQ(number_after(summary, "  lidar               "), 4500) << summary;
  EXPECT_NE(summary.find("MB"), std::string::npos) << summary;
  EXPECT_NE(summary.find("Hz mean"), std::string::npos) << summary;
  // Progress went to stderr about once a second while it ran.
  EXPECT_NE(record.err().find("MB on disk | imu"), std::string::npos) << record.err();

  // Closed and indexed: the summary section is there and its CRC holds.
  rec::McapReader reader;
  std::string error;
  ASSERT_TRUE(reader.open(recording, error)) << error;
  EXPECT_TRUE(reader.summary().usable());
  std::map<std::string, std::vector<std::vector<std::byte>>> by_topic;
  rec::McapMessage m;
  while (reader.next(m)) by_topic[m.channel->topic].emplace_back(m.data.begin(), m.data.end());
  EXPECT_TRUE(reader.complete()) << reader.stop_reason();
  ASSERT_EQ(by_topic["/posed/raw/lidar"].size(), sender.data.size());
  EXPECT_TRUE(by_topic["/posed/raw/lidar"] == sender.data) << "lidar bytes differ from those sent";
  EXPECT_TRUE(by_topic["/posed/raw/lidar/1"] == sender.position);
  EXPECT_GT(by_topic["/posed/raw/imu"].size(), 200u);  // 200 Hz for the whole run

  // The channel records of posed --record (pipeline::recording_metadata).
  for (const auto& [id, c] : reader.channels()) {
    EXPECT_NE(meta(c, "posed.config").find("lidar:"), std::string::npos) << c.topic;
    if (c.topic == "/posed/raw/lidar") {
      EXPECT_EQ(meta(c, "posed.wire_format"), "velodyne-udp-data");
      EXPECT_EQ(meta(c, "posed.lidar.address"), "127.0.0.1");
    }
    if (c.topic == "/posed/raw/imu") {
      EXPECT_EQ(meta(c, "posed.wire_format"), "a9-serial");
      EXPECT_EQ(meta(c, "posed.imu.source"), "synthetic");
    }
  }

  // posectl inspect FILE.mcap lists it: the lidar channel with what was sent, and no error.
  {
    TempDir inspect_dir;
    PosedProcess inspect({build_dir() + "/tools/posectl/posectl", "inspect", recording}, {},
                         inspect_dir);
    ASSERT_EQ(inspect.wait_for_exit(30s), 0) << inspect.out() << inspect.err();
    const std::string listing = inspect.out();
    const auto lidar = listing.find("/posed/raw/lidar\n");
    ASSERT_NE(lidar, std::string::npos) << listing;
    EXPECT_EQ(number_after(listing.substr(lidar), "messages "), 4500) << listing;
    EXPECT_NE(listing.find("state    complete"), std::string::npos) << listing;
    EXPECT_EQ(listing.find("errors ("), std::string::npos) << listing;
  }

  // posed takes the file: every recorded lidar packet and IMU frame is decoded again.
  TempDir replay_dir;
  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording,
                      "--max-speed", "--wait-subscribers", "0"},
                     {}, replay_dir);
  ASSERT_EQ(posed.wait_for_exit(60s), 0) << posed.err();
  const std::string out = posed.out();
  EXPECT_EQ(number_after(out, "  lidar               "), 4500) << out;
  EXPECT_EQ(number_after(out, "  imu                 "),
            static_cast<long long>(by_topic["/posed/raw/imu"].size()))
      << out;
  EXPECT_NE(out.find("lidar scans"), std::string::npos) << out;
}

TEST(PosedRecord, SigkillAtAnyMomentLeavesAFileThatReplaysToItsLastCompleteChunk) {
  // posed --record killed without warning (power cut, OOM killer) at moments drawn from a fixed
  // seed, start-up included: every file that exists reads up to its last complete chunk, says
  // where it stops, loses at most about the recorder's flush interval (1 s) of data, and posed
  // replays exactly what it holds. POSED_CRASH_KILLS sets how many moments (default 3; the issue
  // asks for 20: POSED_CRASH_KILLS=20 build/tests/integration/hil_integration_tests
  // --gtest_filter='PosedRecord.Sigkill*').
  const char* kills_env = std::getenv("POSED_CRASH_KILLS");
  const int kills = kills_env ? std::max(1, std::atoi(kills_env)) : 3;
  std::mt19937 random(20261126);
  std::uniform_real_distribution<double> moment_s(0.2, 4.0);
  int files = 0;
  for (int k = 0; k < kills; ++k) {
    TempDir dir;
    const std::string config =
        dir.write("posed.yaml", dds_config() +
                                    "imu:\n  source: synthetic\n"
                                    "synthetic_imu:\n  static_s: 1.5\n  ramp_s: 2\n"
                                    "estimator:\n  init_static_s: 0.5\n");
    const std::string recording = dir.file("run.mcap");
    const double kill_at_s = moment_s(random);
    std::optional<std::chrono::steady_clock::time_point> recording_since;
    std::chrono::steady_clock::time_point killed_at;
    {
      PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--record", recording},
                         {}, dir);
      const auto start = std::chrono::steady_clock::now();
      const auto kill_at = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                       std::chrono::duration<double>(kill_at_s));
      while (std::chrono::steady_clock::now() < kill_at) {
        ASSERT_FALSE(posed.wait_for_exit(5ms).has_value()) << posed.err();
        if (!recording_since && posed.err().find("recording raw streams") != std::string::npos) {
          recording_since = std::chrono::steady_clock::now();
        }
      }
      posed.signal(SIGKILL);
      killed_at = std::chrono::steady_clock::now();
      ASSERT_EQ(posed.wait_for_exit(5s), -1) << "killed at " << kill_at_s << " s";
    }
    SCOPED_TRACE("SIGKILL " + std::to_string(k + 1) + " at " + std::to_string(kill_at_s) + " s");
    if (!std::filesystem::exists(recording)) {
      std::printf("SIGKILL %d at %.2f s: no file yet (start-up)\n", k + 1, kill_at_s);
      EXPECT_FALSE(recording_since.has_value()) << "posed said it recorded, and left no file";
      continue;
    }
    ++files;
    rec::McapReader reader;
    std::string error;
    ASSERT_TRUE(reader.open(recording, error)) << error;
    std::size_t imu = 0;
    rec::McapMessage m;
    while (reader.next(m)) imu += m.channel->topic == "/posed/raw/imu";
    EXPECT_FALSE(reader.complete()) << "no footer can have been written";
    EXPECT_FALSE(reader.stop_reason().empty());
    if (recording_since) {
      // The synthetic A9 at 200 Hz; what the recorder held in its last second may be lost.
      const double recorded_s = std::chrono::duration<double>(killed_at - *recording_since).count();
      EXPECT_GE(static_cast<double>(imu), 200.0 * (recorded_s - 1.5))
          << imu << " IMU frames in a file recorded for " << recorded_s << " s";
      std::printf("SIGKILL %d at %.2f s: recording for %.2f s, %zu IMU frames (%.2f s) kept, %s\n",
                  k + 1, kill_at_s, recorded_s, imu, static_cast<double>(imu) / 200.0,
                  reader.stop_reason().c_str());
    }
    if (imu == 0) continue;  // killed before the first chunk was flushed: nothing to replay

    TempDir replay_dir;
    PosedProcess replay({build_dir() + "/daemon/posed", "--config", config, "--replay", recording,
                         "--max-speed", "--wait-subscribers", "0"},
                        {}, replay_dir);
    ASSERT_EQ(replay.wait_for_exit(60s), 0) << replay.err();
    EXPECT_EQ(number_after(replay.out(), "  imu                 "), static_cast<long long>(imu))
        << replay.out();
    EXPECT_NE(replay.err().find("recording damaged"), std::string::npos) << replay.err();
  }
  std::printf("%d of %d SIGKILLed recordings left a file; every one read to its last chunk\n",
              files, kills);
}

TEST(PosectlRecord, DurationAndSplitSizeMakeSeveralCompleteFiles) {
  TempDir dir;
  const std::string config = dir.write("posed.yaml", dds_config() + "imu:\n  source: synthetic\n" +
                                                         "synthetic_imu:\n  rate_hz: 1000\n");
  const std::string recording = dir.file("split.mcap");
  TempDir record_dir;
  // The synthetic A9 gives ~49 kB/s at 1000 Hz; 0.02 MB files rotate every ~0.4 s.
  PosedProcess record({build_dir() + "/tools/posectl/posectl", "record", "-o", recording,
                       "--config", config, "--duration", "2", "--split-size", "0.02"},
                      {}, record_dir);
  ASSERT_EQ(record.wait_for_exit(30s), 0) << record.err();
  EXPECT_NE(record.out().find("stopped by          --duration"), std::string::npos) << record.out();
  std::vector<std::string> files = {recording};
  for (int i = 1;; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "split_%03d.mcap", i);  // the Recorder's rotation names
    if (!std::filesystem::exists(dir.file(name))) break;
    files.push_back(dir.file(name));
  }
  ASSERT_GE(files.size(), 3u) << record.out();
  std::uint64_t total = 0;
  for (const auto& f : files) {
    rec::McapReader reader;
    std::string error;
    ASSERT_TRUE(reader.open(f, error)) << error;
    EXPECT_TRUE(reader.summary().usable()) << f;
    rec::McapMessage m;
    while (reader.next(m)) ++total;
    EXPECT_TRUE(reader.complete()) << f << ": " << reader.stop_reason();
  }
  EXPECT_EQ(static_cast<long long>(total), number_after(record.out(), "  imu                 "));
}

TEST(PosectlRecord, ABadConfigIsRefusedNamingTheKey) {
  TempDir dir;
  const std::string config = dir.write("posed.yaml", "imu:\n  sourcee: synthetic\n");
  PosedProcess record({build_dir() + "/tools/posectl/posectl", "record", "-o", dir.file("x.mcap"),
                       "--config", config},
                      {}, dir);
  ASSERT_EQ(record.wait_for_exit(10s), 2);
  EXPECT_NE(record.err().find("imu.sourcee"), std::string::npos) << record.err();
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.mcap")));
}

/// The VLP-32C's manual table as a ros-drivers calibration YAML file's text.
std::string vlp32c_calibration_yaml() {
  const auto table = drivers::velodyne::builtin_calibration(drivers::velodyne::ProductId::kVlp32c);
  std::string yaml = "num_lasers: 32\ndistance_resolution: 0.004\nlasers:\n";
  for (std::size_t i = 0; i < table.lasers.size(); ++i) {
    char line[160];
    std::snprintf(line, sizeof line,
                  "  - {laser_id: %zu, rot_correction: %.9f, vert_correction: %.9f}\n", i,
                  table.lasers[i].rot_correction_rad, table.lasers[i].vert_correction_rad);
    yaml += line;
  }
  return yaml;
}

// A laptop replays a robot's recording with the configuration the robot ran: settings and the
// lidar calibration come from the file (the calibration file itself is gone), DDS from the
// laptop's --config.
TEST(PosedReplay, RecordedConfigReplaysAsTheRobotRanWithTheRecordedCalibration) {
  TempDir robot;
  const std::uint16_t data_port = free_udp_port();
  const std::uint16_t position_port = free_udp_port();
  const std::string calibration = robot.write("vlp32c.yaml", vlp32c_calibration_yaml());
  const std::string robot_config =
      robot.write("posed.yaml", dds_config() +
                                    "imu:\n  source: synthetic\n"
                                    "synthetic_imu:\n  static_s: 1.5\n  ramp_s: 2\n  rate_hz: 250\n"
                                    "lidar:\n  enabled: true\n  source: udp\n  address: 127.0.0.1\n"
                                    "  calibration: vlp32c.yaml\n  data_port: " +
                                    std::to_string(data_port) +
                                    "\n  position_port: " + std::to_string(position_port) + "\n" +
                                    "estimator:\n  init_static_s: 0.5\n");
  const std::string recording = robot.file("run.mcap");
  {
    PosedProcess record({build_dir() + "/tools/posectl/posectl", "record", "-o", recording,
                         "--config", robot_config},
                        {}, robot);
    ASSERT_NO_FATAL_FAILURE(wait_until_recording(record));
    LidarSender sender;
    sender.run(data_port, position_port, 1500);
    std::this_thread::sleep_for(500ms);
    record.signal(SIGINT);
    ASSERT_EQ(record.wait_for_exit(30s), 0) << record.err();
  }
  std::filesystem::remove(calibration);

  TempDir laptop;
  const std::string laptop_config = laptop.write("local.yaml", dds_config());
  const std::string posed = build_dir() + "/daemon/posed";
  // What it runs with: the robot's settings, the laptop's DDS.
  {
    PosedProcess print({posed, "--replay", recording, "--recorded-config", "--config",
                        laptop_config, "--print-config"},
                       {}, laptop);
    ASSERT_EQ(print.wait_for_exit(30s), 0) << print.err();
    const std::string printed = print.out();
    EXPECT_NE(printed.find("data_port: " + std::to_string(data_port)), std::string::npos)
        << printed;
    EXPECT_NE(printed.find("rate_hz: 250"), std::string::npos) << printed;
    EXPECT_NE(printed.find("cyclonedds-loopback.xml"), std::string::npos) << printed;
  }
  // The laptop's own config has no such calibration file: a plain replay cannot decode.
  {
    PosedProcess plain({posed, "--replay", recording, "--config", robot_config, "--max-speed",
                        "--wait-subscribers", "0"},
                       {}, laptop);
    ASSERT_NE(plain.wait_for_exit(60s), 0);
    EXPECT_NE(plain.err().find("vlp32c.yaml"), std::string::npos) << plain.err();
  }
  PosedProcess replay({posed, "--replay", recording, "--recorded-config", "--config", laptop_config,
                       "--max-speed", "--wait-subscribers", "0"},
                      {}, laptop);
  ASSERT_EQ(replay.wait_for_exit(60s), 0) << replay.err();
  EXPECT_NE(replay.err().find("configuration as recorded in " + recording), std::string::npos)
      << replay.err();
  EXPECT_NE(replay.err().find("(recorded " + calibration + ")"), std::string::npos) << replay.err();
  EXPECT_EQ(number_after(replay.out(), "  lidar               "), 1500) << replay.out();
}

TEST(PosedReplay, RecordedConfigOfARecordingWithoutOneIsRefusedNamingTheFile) {
  TempDir dir;
  const std::string simulated = dir.file("sim.mcap");
  PosedProcess sim(
      {simulator(), "sim", "--scenario", "room", "--duration", "0.5", "--seed", "1", "--no-cameras",
       "--config", source_dir() + "/config/posed.yaml", "-o", simulated},
      {}, dir);
  ASSERT_EQ(sim.wait_for_exit(60s), 0) << sim.err();
  PosedProcess replay(
      {build_dir() + "/daemon/posed", "--replay", simulated, "--recorded-config", "--max-speed"},
      {}, dir);
  ASSERT_EQ(replay.wait_for_exit(30s), 2) << replay.err();
  EXPECT_NE(replay.err().find(simulated + ": no recorded configuration"), std::string::npos)
      << replay.err();
}

// A recording whose pose stream went out of order (posed before 878f2f7 could send the back end's
// first propagation, then a first scan state stamped 0.145 ms before it): posectl export leaves
// the late one out, says so, and writes a TUM file posectl eval takes.
TEST(PosectlExport, LeavesOutAPoseStampedBeforeTheOneBeforeAndSaysSo) {
  TempDir dir;
  const std::string recording = dir.file("poses.mcap");
  {
    drivers::recording::RecorderOptions opt;
    opt.writer.fsync_on_close = false;
    opt.in_push_order = true;  // as written, like posed's own pose stream
    opt.host_to_wall.wall_minus_host = Duration::from_s(1'700'000'000);
    drivers::recording::Recorder rec;
    std::string error;
    ASSERT_TRUE(rec.open(recording, opt, error)) << error;
    for (const std::int64_t ns :
         {1'027'275'528LL, 1'027'130'784LL, 1'127'106'600LL, 1'227'137'264LL}) {
      ASSERT_TRUE(rec.write_pose("/posed/pose", WallTime::from_ns(1'700'000'000'000'000'000 + ns),
                                 "map", {1e-9 * static_cast<double>(ns), 0, 0}, {0, 0, 0, 1}));
    }
    ASSERT_TRUE(rec.close());
  }
  const std::string tum = dir.file("poses.tum");
  PosedProcess exporter({build_dir() + "/tools/posectl/posectl", "export", recording, "--tum", tum},
                        {}, dir);
  ASSERT_EQ(exporter.wait_for_exit(30s), 0) << exporter.err();
  EXPECT_NE(exporter.err().find("3 poses from /posed/pose"), std::string::npos) << exporter.err();
  EXPECT_NE(exporter.err().find("1 left out: stamped no later than the pose before"),
            std::string::npos)
      << exporter.err();
  PosedProcess eval({build_dir() + "/tools/posectl/posectl", "eval", "--gt", tum, "--est", tum,
                     "--align", "none"},
                    {}, dir);
  EXPECT_EQ(eval.wait_for_exit(30s), 0) << eval.err() << eval.out();
}

}  // namespace record_test
}  // namespace posed::testing
