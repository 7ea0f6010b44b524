// A CAN IMU end to end, as a user with a candump log runs it: frames of a known motion (standing
// still, then turning at a constant rate about the vertical, gravity throughout) are encoded with
// config/imu-can-example.yaml's mapping and written as a `candump -l` log; `posectl import` turns
// it into /posed/raw/imu (linux-can-frame); `posed --replay` decodes it with the mapping, and
// every sample must reach the fusion core and turn the estimate by the commanded angle. The
// device's u32 µs counter wraps during the run.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <thread>

#include "daemon/config/config_loader.hpp"
#include "daemon/pipeline/pipeline.hpp"
#include "daemon/pipeline/replay_sources.hpp"
#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "tests/common/can_imu_encoder.hpp"
#include "tests/integration/posed_process.hpp"

namespace posed::testing {
namespace can_replay_test {

using namespace std::chrono_literals;
namespace rec = drivers::recording;

int test_domain() { return 1 + static_cast<int>((::getpid() + 73) % 99); }

constexpr int kRateHz = 200;
constexpr int kStaticSamples = 500;  // 2.5 s standing still (gravity alignment)
constexpr int kSamples = 1300;       // then 4 s turning
constexpr double kYawRateRadps = 0.5;
constexpr double kGravity = 9.805;
/// candump's wall clock at the first frame [µs]
constexpr std::int64_t kStartUs = 1'700'000'000'000'000;
/// the device counter at the first sample: wraps (2^32 µs) about 1.5 s in [µs]
constexpr std::uint64_t kCounter0 = 4'293'467'296;

/// The log, with a frame of another device on the bus every tenth sample.
std::string candump_log(const drivers::can::CanImuMapping& mapping) {
  std::string log;
  drivers::can::CanFrame other;
  other.id = 0x700;
  other.len = 2;
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector3d gyro(0, 0, i < kStaticSamples ? 0.0 : kYawRateRadps);
    const Eigen::Vector3d force(0, 0, kGravity);
    const auto counter = static_cast<std::uint32_t>(kCounter0 + 5000ull * static_cast<unsigned>(i));
    // Bus and USB jitter: frames arrive 0.1 ms apart plus up to 0.3 ms late.
    std::int64_t t = kStartUs + 5000LL * i + 300LL * ((i * 37) % 11) / 10;
    for (const auto& f : test::encode_can_imu_sample(mapping, gyro, force, counter)) {
      log += test::candump_line(t, f);
      t += 100;
    }
    if (i % 10 == 0) log += test::candump_line(t, other);
  }
  return log;
}

TEST(CanReplay, ACandumpImportReplaysIntoTheFusionCore) {
  const config::LoadResult example =
      config::load_config_file(source_dir() + "/config/imu-can-example.yaml");
  ASSERT_TRUE(example.ok()) << example.error_text();
  const drivers::can::CanImuMapping& mapping = example.config.imu.can_mapping;

  TempDir dir;
  const std::string log = dir.write("imu.log", candump_log(mapping));
  const std::string imported = dir.file("imu.mcap");
  {
    PosedProcess import({build_dir() + "/tools/posectl/posectl", "import", log, "-o", imported}, {},
                        dir);
    ASSERT_EQ(import.wait_for_exit(60s), 0) << import.err() << import.out();
    EXPECT_NE(import.out().find("candump log"), std::string::npos) << import.out();
    EXPECT_NE(import.out().find("posed streams: imu"), std::string::npos) << import.out();
  }
  {
    rec::McapReader reader;
    std::string error;
    ASSERT_TRUE(reader.open(imported, error)) << error;
    ASSERT_EQ(reader.channels().size(), 1u);
    const rec::McapChannelRecord& c = reader.channels().begin()->second;
    EXPECT_EQ(c.topic, "/posed/raw/imu");
    EXPECT_EQ(c.metadata.at(std::string(rec::raw::kWireFormatKey)), rec::raw::kWireCanFrame);
  }

  // posed as a user runs it: the example's imu section, DDS on loopback in a domain of its own.
  const std::string config =
      dir.write("posed.yaml", loopback_dds_yaml(test_domain()) +
                                  "imu:\n  source: can\n  rate_hz: " + std::to_string(kRateHz) +
                                  "\n  can_mapping: " + config::can_mapping_yaml(mapping) + "\n");
  {
    PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", imported,
                        "--max-speed", "--wait-subscribers", "0"},
                       {}, dir);
    ASSERT_EQ(posed.wait_for_exit(120s), 0) << posed.err() << posed.out();
    EXPECT_NE(posed.out().find("imu                 " + std::to_string(kSamples) + " decoded"),
              std::string::npos)
        << posed.out();
    EXPECT_NE(posed.out().find(" 0 malformed, 0 dropped; clock locked"), std::string::npos)
        << posed.out();
    EXPECT_EQ(posed.err().find("no decoder for wire format"), std::string::npos) << posed.err();
    EXPECT_EQ(posed.err().find("imu clock: reset"), std::string::npos)
        << "the counter's wrap is not a reset: " << posed.err();
  }

  // Without imu.can_mapping nothing says which frames are the IMU's: every frame is counted as
  // malformed, said apart as a configuration problem, and the log says where a mapping comes from.
  {
    const std::string unmapped = dir.write("unmapped.yaml", loopback_dds_yaml(test_domain()));
    PosedProcess posed({build_dir() + "/daemon/posed", "--config", unmapped, "--replay", imported,
                        "--max-speed", "--wait-subscribers", "0"},
                       {}, dir);
    posed.wait_for_exit(120s);
    const std::string log_text = candump_log(mapping);  // one frame per line
    const std::string frames = std::to_string(std::count(log_text.begin(), log_text.end(), '\n'));
    EXPECT_NE(posed.out().find("imu                 0 decoded"), std::string::npos) << posed.out();
    EXPECT_NE(
        posed.out().find(" " + frames + " malformed (" + frames + " with no decoder configured)"),
        std::string::npos)
        << posed.out();
    EXPECT_NE(posed.err().find("no imu.can_mapping"), std::string::npos) << posed.err();
    EXPECT_NE(posed.err().find("--recorded-config"), std::string::npos) << posed.err();
  }

  // The same replay in process (make_replay_sources + Pipeline, as posed --replay builds it), to
  // look at what the fusion core made of the samples.
  config::LoadResult loaded = config::load_config_file(config);
  ASSERT_TRUE(loaded.ok()) << loaded.error_text();
  pipeline::ReplayOptions options;
  options.path = imported;
  options.rate = 0;
  std::string error;
  pipeline::ReplaySources replay = pipeline::make_replay_sources(options, error);
  ASSERT_TRUE(error.empty()) << error;
  std::mutex m;
  std::vector<NavState> states;
  pipeline::PipelineStatus status;
  pipeline::PipelineOutputs outputs;
  outputs.on_state = [&](const NavState& s, const Eigen::Isometry3d&) {
    std::lock_guard lock(m);
    states.push_back(s);
  };
  outputs.on_status = [&](const pipeline::PipelineStatus& st) {
    std::lock_guard lock(m);
    status = st;
  };
  pipeline::Pipeline pipe(loaded.config, std::move(replay.built.sources), std::move(outputs));
  ASSERT_TRUE(pipe.start(error)) << error;
  for (int i = 0; i < 3000 && !pipe.finished(); ++i) std::this_thread::sleep_for(10ms);
  ASSERT_TRUE(pipe.finished()) << "the replay did not drain within 30 s";
  pipe.join();

  const pipeline::StreamStatus& imu = status.streams.at(0);
  EXPECT_EQ(imu.decoded, static_cast<std::uint64_t>(kSamples));
  EXPECT_EQ(imu.malformed, 0u);
  EXPECT_EQ(imu.dropped, 0u);
  EXPECT_EQ(imu.clock_state, "locked");
  // Alignment takes estimator.init_static_s (1 s) of samples; every later one gives a state.
  ASSERT_GE(states.size(), static_cast<std::size_t>(kSamples - kRateHz - 2));
  EXPECT_LE(states.size(), static_cast<std::size_t>(kSamples));
  EXPECT_EQ(status.states, states.size());
  // Stamps on the candump clock, 5 ms apart.
  for (std::size_t i = 1; i < states.size(); ++i) {
    ASSERT_NEAR((states[i].stamp - states[i - 1].stamp).seconds(), 0.005, 1e-4) << i;
  }
  EXPECT_NEAR(static_cast<double>(states.back().stamp.ns) * 1e-3,
              static_cast<double>(kStartUs + 5000LL * (kSamples - 1)), 2000.0);
  // Turned about the vertical by the rate times the turning time (the gyro's 0.01 deg/s
  // quantisation: 0.5 rad/s is 2864.8 counts, read as 2865).
  const Eigen::AngleAxisd turn(states.front().q_map_base.inverse() * states.back().q_map_base);
  const double turning_s = static_cast<double>(kSamples - kStaticSamples - 1) / kRateHz;
  EXPECT_NEAR(turn.angle(), kYawRateRadps * turning_s, 0.01);
  EXPECT_GT(turn.axis().z(), 0.999) << turn.axis().transpose();
  EXPECT_NEAR(states.back().w_base_radps.z(), kYawRateRadps, 1e-3);
  // Gravity only: the estimate stays put (1 mg quantisation of the accelerometer).
  EXPECT_LT(states.back().p_map_base_m.norm(), 0.05) << states.back().p_map_base_m.transpose();
}

}  // namespace can_replay_test
}  // namespace posed::testing
