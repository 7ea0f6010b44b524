// The IMU stage on Linux CAN frames (imu_stage_can.cpp): chunks in the wire format
// linux-can-frame are decoded by imu.can_mapping (config/imu-can-example.yaml), rotated by
// imu.R_imu_sensor, stamped through ClockSync from the mapped counter (or at arrival without
// one) and queued like the A9's samples; malformed frames are counted and skipped. A live CAN
// IMU records its frames in that wire format, and the recording replays to the same samples.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "daemon/config/config_loader.hpp"
#include "daemon/pipeline/imu_stage.hpp"
#include "daemon/pipeline/recording_tap.hpp"
#include "daemon/pipeline/source_factory.hpp"
#include "drivers/common/wire_format.hpp"
#include "drivers/recording/mcap_replay_source.hpp"
#include "drivers/recording/recorder.hpp"
#include "tests/common/can_imu_encoder.hpp"

namespace posed::pipeline {
namespace imu_stage_can_test {

namespace can = drivers::can;

/// Hands out prepared chunks of one wire format on channel 0, then ends; not live (lossless).
class ChunkSource final : public drivers::Source {
 public:
  ChunkSource(std::string format, std::vector<std::pair<std::int64_t, std::vector<std::byte>>> c)
      : format_(std::move(format)), chunks_(std::move(c)) {}
  std::string_view name() const override { return "imu"; }
  bool open(std::string&) override { return true; }
  drivers::ReadStatus read(drivers::RawChunk& chunk, Duration) override {
    if (next_ >= chunks_.size()) return drivers::ReadStatus::kEndOfStream;
    chunk.channel = 0;
    chunk.host_receive = HostTime::from_ns(chunks_[next_].first);
    chunk.bytes = chunks_[next_].second;
    ++next_;
    return drivers::ReadStatus::kData;
  }
  void request_stop() override {}
  drivers::SourceCounters counters() const override { return {}; }
  std::string_view wire_format(std::uint32_t channel) const override {
    return channel == 0 ? std::string_view(format_) : std::string_view{};
  }
  bool live() const override { return false; }

 private:
  std::string format_;
  std::vector<std::pair<std::int64_t, std::vector<std::byte>>> chunks_;
  std::size_t next_ = 0;
};

std::vector<std::byte> kernel_bytes(const can::CanFrame& f) {
  std::vector<std::byte> out(can::kCanFdMtu);
  const std::size_t n =
      can::to_kernel_bytes(f, {reinterpret_cast<std::uint8_t*>(out.data()), out.size()});
  out.resize(n);
  return out;
}

config::PosedConfig example_config() {
  const char* src = std::getenv("POSED_SOURCE_DIR");
  EXPECT_NE(src, nullptr) << "POSED_SOURCE_DIR is set by ctest";
  const config::LoadResult r =
      config::load_config_file(std::string(src ? src : ".") + "/config/imu-can-example.yaml");
  EXPECT_TRUE(r.ok()) << r.error_text();
  config::PosedConfig c = r.config;
  // Mounted turned 90 degrees about z: sensor x is the IMU frame's y.
  c.imu.R_imu_sensor = {0, -1, 0, 1, 0, 0, 0, 0, 1};
  return c;
}

const Eigen::Vector3d kGyro(0.1, -0.2, 0.5);             // [rad/s], sensor axes
const Eigen::Vector3d kForce(0.3, -0.1, 9.80665);        // [m/s^2], sensor axes
constexpr std::int64_t kT0 = 1'600'000'000'000'000'000;  // first arrival [ns]
constexpr std::int64_t kPeriod = 5'000'000;              // 200 Hz [ns]

/// `n` samples of the constant motion, as the example IMU's frames, 0.2 ms apart on the bus.
std::vector<std::pair<std::int64_t, std::vector<std::byte>>> frames(
    const can::CanImuMapping& mapping, int n) {
  std::vector<std::pair<std::int64_t, std::vector<std::byte>>> out;
  for (int i = 0; i < n; ++i) {
    const auto counter = static_cast<std::uint64_t>(1000 + 5000 * i);
    std::int64_t t = kT0 + kPeriod * i;
    for (const auto& f : test::encode_can_imu_sample(mapping, kGyro, kForce, counter)) {
      out.emplace_back(t, kernel_bytes(f));
      t += 200'000;
    }
  }
  return out;
}

struct StageRun {
  std::vector<ImuSample> samples;
  bool ended = false;
  std::uint64_t decoded = 0, malformed = 0, undecodable = 0, received = 0;
};

StageRun run_stage(const config::PosedConfig& config, drivers::Source& source) {
  SpscQueue<ImuItem> queue(4096, DropPolicy::kBlockWithTimeout, std::chrono::seconds(5));
  Wakeup wakeup;
  Heartbeat heartbeat("imu");
  StreamCounters counters;
  ImuStage stage(config, source, queue, wakeup, heartbeat, counters);
  stage.run();
  StageRun r;
  while (auto item = queue.pop()) {
    if (item->end_of_stream) {
      r.ended = true;
      break;
    }
    r.samples.push_back(item->sample);
  }
  r.decoded = counters.decoded.load();
  r.malformed = counters.malformed.load();
  r.undecodable = counters.undecodable.load();
  r.received = counters.received.load();
  return r;
}

TEST(ImuStageCan, FramesBecomeRotatedSamplesInSiUnitsOnTheHostClock) {
  const config::PosedConfig config = example_config();
  auto chunks = frames(config.imu.can_mapping, 40);
  ChunkSource source(std::string(drivers::wire::kCanFrame), chunks);
  const StageRun r = run_stage(config, source);
  ASSERT_TRUE(r.ended);
  ASSERT_EQ(r.samples.size(), 40u);
  EXPECT_EQ(r.decoded, 40u);
  EXPECT_EQ(r.malformed, 0u);
  EXPECT_EQ(r.undecodable, 0u);
  // R_imu_sensor turns sensor x into IMU y and sensor y into IMU -x.
  const Eigen::Vector3d gyro_imu(-kGyro.y(), kGyro.x(), kGyro.z());
  const Eigen::Vector3d force_imu(-kForce.y(), kForce.x(), kForce.z());
  for (const ImuSample& s : r.samples) {
    // Quantisation: 0.01 deg/s and 1 mg per count.
    EXPECT_LT((s.angular_velocity_radps - gyro_imu).norm(), 1.5e-4) << s.angular_velocity_radps;
    EXPECT_LT((s.specific_force_mps2 - force_imu).norm(), 1e-2) << s.specific_force_mps2;
  }
  // The µs counter is the device clock: 5 ms apart, mapped near the completing frames' arrival.
  for (std::size_t i = 1; i < r.samples.size(); ++i) {
    EXPECT_EQ((r.samples[i].device_stamp - r.samples[i - 1].device_stamp).ns, kPeriod) << i;
    EXPECT_NEAR(static_cast<double>((r.samples[i].stamp - r.samples[i - 1].stamp).ns),
                static_cast<double>(kPeriod), 1e4)
        << i;
  }
  const std::int64_t last_arrival = kT0 + kPeriod * 39 + 2 * 200'000;
  EXPECT_LE(r.samples.back().stamp.ns, last_arrival);
  EXPECT_GT(r.samples.back().stamp.ns, last_arrival - 2'000'000);
}

TEST(ImuStageCan, MalformedFramesAreCountedAndSkipped) {
  const config::PosedConfig config = example_config();
  auto chunks = frames(config.imu.can_mapping, 10);
  // Not a kernel frame (5 bytes); an accel frame cut to 4 bytes (accel_z lies beyond it); a
  // frame of another device on the bus (ignored, not malformed); a sample whose gyro frame was
  // lost (the completing frame comes with gyro missing).
  chunks.insert(chunks.begin() + 3, {kT0 + 1, std::vector<std::byte>(5)});
  can::CanFrame short_accel;
  short_accel.id = 0x182;
  short_accel.len = 4;
  chunks.insert(chunks.begin() + 7, {kT0 + 2, kernel_bytes(short_accel)});
  can::CanFrame other;
  other.id = 0x700;
  other.len = 1;
  chunks.insert(chunks.begin() + 8, {kT0 + 3, kernel_bytes(other)});
  // Sample 5's frames are at 3 (+3 inserted) .. : drop the gyro frame of the last sample.
  chunks.erase(chunks.end() - 2);
  ChunkSource source(std::string(drivers::wire::kCanFrame), chunks);
  const StageRun r = run_stage(config, source);
  EXPECT_EQ(r.malformed, 3u);
  EXPECT_EQ(r.decoded, 9u) << "the last sample lost its gyro frame";
  EXPECT_EQ(r.samples.size(), 9u);
  EXPECT_EQ(r.received, chunks.size());
}

TEST(ImuStageCan, WithoutACounterSamplesAreStampedAtArrival) {
  config::PosedConfig config = example_config();
  auto& fields = config.imu.can_mapping.fields;
  fields.erase(fields.begin());  // the counter
  config.imu.clock_latency_s = 0.001;
  ChunkSource source(std::string(drivers::wire::kCanFrame), frames(config.imu.can_mapping, 5));
  const StageRun r = run_stage(config, source);
  ASSERT_EQ(r.samples.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    // Two frames per sample now: the completing one arrives 0.2 ms after the first.
    const std::int64_t arrival = kT0 + kPeriod * static_cast<std::int64_t>(i) + 200'000;
    EXPECT_EQ(r.samples[i].stamp.ns, arrival - 1'000'000) << i;
  }
}

TEST(ImuStageCan, WithoutAMappingCanFramesAreUndecodable) {
  const config::PosedConfig example = example_config();
  config::PosedConfig config = config::default_config();
  ChunkSource source(std::string(drivers::wire::kCanFrame), frames(example.imu.can_mapping, 4));
  const StageRun r = run_stage(config, source);
  EXPECT_TRUE(r.samples.empty());
  EXPECT_EQ(r.undecodable, 12u);
  EXPECT_EQ(r.malformed, 0u);
}

TEST(ImuStageCan, ALiveCanImuIsASocketCanSourceRecordedAsCanFrames) {
  config::PosedConfig config = example_config();
  config.imu.can_interface = "posedcan9";  // no such interface
  std::string error;
  BuiltSources built = make_sources(config, error);
  ASSERT_TRUE(error.empty()) << error;
  ASSERT_NE(built.sources.imu, nullptr);
  EXPECT_EQ(built.sources.imu->name(), "imu");
  EXPECT_EQ(built.sources.imu->wire_format(0), drivers::wire::kCanFrame);
  EXPECT_TRUE(built.sources.imu->live());
  // Absent (or no PF_CAN at all): open() fails, naming the interface, as the serial port does.
  EXPECT_FALSE(built.sources.imu->open(error));
  EXPECT_NE(error.find("SocketCAN posedcan9"), std::string::npos) << error;

  // A recording of it: the tap stores the frames as linux-can-frame with the mapping, and the
  // replay decodes them to the very samples the live stage made.
  const auto path = std::filesystem::temp_directory_path() /
                    ("posed_can_tap_" + std::to_string(::getpid()) + ".mcap");
  const auto chunks = frames(config.imu.can_mapping, 20);
  drivers::recording::Recorder recorder;
  drivers::recording::RecorderOptions options;
  options.writer.fsync_on_close = false;
  ASSERT_TRUE(recorder.open(path.string(), options, error)) << error;
  PipelineSources sources;
  sources.imu = std::make_unique<ChunkSource>(std::string(drivers::wire::kCanFrame), chunks);
  tap_sources(sources, recorder, config);
  const StageRun live = run_stage(config, *sources.imu);
  ASSERT_TRUE(recorder.close()) << recorder.error();
  ASSERT_EQ(live.samples.size(), 20u);

  drivers::recording::McapReplayConfig replay;
  replay.path = path.string();
  replay.stream = "imu";
  replay.rate = 0;
  drivers::recording::McapReplaySource source(replay);
  ASSERT_TRUE(source.open(error)) << error;
  const auto channels = source.channels();
  ASSERT_EQ(channels.size(), 1u);
  EXPECT_EQ(channels[0].wire_format, drivers::wire::kCanFrame);
  EXPECT_EQ(channels[0].metadata.at("posed.imu.source"), "can");
  EXPECT_EQ(channels[0].metadata.at("posed.imu.device"), "posedcan9");
  EXPECT_EQ(channels[0].metadata.at("posed.imu.can_mapping"),
            config::can_mapping_yaml(config.imu.can_mapping));
  const StageRun replayed = run_stage(config, source);
  ASSERT_EQ(replayed.samples.size(), live.samples.size());
  for (std::size_t i = 0; i < live.samples.size(); ++i) {
    EXPECT_EQ(replayed.samples[i].stamp, live.samples[i].stamp) << i;
    EXPECT_EQ(replayed.samples[i].angular_velocity_radps, live.samples[i].angular_velocity_radps);
    EXPECT_EQ(replayed.samples[i].specific_force_mps2, live.samples[i].specific_force_mps2);
  }
  std::filesystem::remove(path);
}

}  // namespace imu_stage_can_test
}  // namespace posed::pipeline
