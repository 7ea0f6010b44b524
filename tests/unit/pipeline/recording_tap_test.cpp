// tap_sources(): every Source PipelineSources holds is recorded, channel by channel, with the
// metadata posed --record and posectl record both store, while reads pass through unchanged.

#include "daemon/pipeline/recording_tap.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <vector>

#include "daemon/config/config_loader.hpp"
#include "drivers/recording/mcap_reader.hpp"

namespace posed::pipeline {
namespace recording_tap_test {

/// Hands out scripted chunks (channel, bytes), then ends.
class ScriptedSource final : public drivers::Source {
 public:
  ScriptedSource(std::string name, std::vector<std::string> formats,
                 std::vector<std::pair<std::uint32_t, std::vector<std::byte>>> chunks)
      : name_(std::move(name)), formats_(std::move(formats)), chunks_(std::move(chunks)) {}
  std::string_view name() const override { return name_; }
  bool open(std::string&) override { return true; }
  drivers::ReadStatus read(drivers::RawChunk& chunk, Duration) override {
    if (next_ >= chunks_.size()) return drivers::ReadStatus::kEndOfStream;
    chunk.channel = chunks_[next_].first;
    chunk.bytes = chunks_[next_].second;
    chunk.host_receive = HostTime::from_ns(1'000'000 * static_cast<std::int64_t>(next_ + 1));
    ++next_;
    return drivers::ReadStatus::kData;
  }
  void request_stop() override {}
  drivers::SourceCounters counters() const override { return {}; }
  std::string_view wire_format(std::uint32_t channel) const override {
    return channel < formats_.size() ? std::string_view(formats_[channel]) : std::string_view{};
  }

 private:
  std::string name_;
  std::vector<std::string> formats_;
  std::vector<std::pair<std::uint32_t, std::vector<std::byte>>> chunks_;
  std::size_t next_ = 0;
};

std::vector<std::byte> bytes(std::initializer_list<int> v) {
  std::vector<std::byte> out;
  for (int b : v) out.push_back(static_cast<std::byte>(b));
  return out;
}

TEST(RecordingTap, EverySourceIsRecordedWithItsMetadataAndReadsPassThrough) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("posed_tap_" + std::to_string(::getpid()) + ".mcap");
  config::PosedConfig config = config::default_config();
  config.imu.source = "serial";
  config.imu.serial_device = "/dev/ttyA9";
  config.lidar.address = "10.0.0.7";

  PipelineSources sources;
  sources.imu = std::make_unique<ScriptedSource>(
      "imu", std::vector<std::string>{"a9-serial"},
      std::vector<std::pair<std::uint32_t, std::vector<std::byte>>>{{0, bytes({0xAA, 0x55})},
                                                                    {0, bytes({0x01})}});
  sources.lidar = std::make_unique<ScriptedSource>(
      "lidar", std::vector<std::string>{"velodyne-udp-data", "velodyne-udp-position"},
      std::vector<std::pair<std::uint32_t, std::vector<std::byte>>>{
          {0, bytes({1, 2, 3})}, {1, bytes({9})}, {0, bytes({4, 5})}});

  drivers::recording::Recorder recorder;
  drivers::recording::RecorderOptions options;
  options.writer.fsync_on_close = false;
  std::string error;
  ASSERT_TRUE(recorder.open(path.string(), options, error)) << error;
  tap_sources(sources, recorder, config);

  // The tapped Sources still hand out exactly what the inner ones read.
  std::vector<std::vector<std::byte>> passed;
  sources.for_each([&](std::unique_ptr<drivers::Source>& s) {
    if (!s) return;  // the cameras are not set here
    drivers::RawChunk c;
    while (s->read(c, Duration::from_ms(1)) == drivers::ReadStatus::kData) {
      passed.emplace_back(c.bytes.begin(), c.bytes.end());
    }
  });
  EXPECT_EQ(passed.size(), 5u);
  ASSERT_TRUE(recorder.close()) << recorder.error();

  drivers::recording::McapReader reader;
  ASSERT_TRUE(reader.open(path.string(), error)) << error;
  std::map<std::string, std::vector<std::vector<std::byte>>> by_topic;
  drivers::recording::McapMessage m;
  while (reader.next(m)) by_topic[m.channel->topic].emplace_back(m.data.begin(), m.data.end());
  EXPECT_EQ(by_topic["/posed/raw/imu"],
            (std::vector<std::vector<std::byte>>{bytes({0xAA, 0x55}), bytes({0x01})}));
  EXPECT_EQ(by_topic["/posed/raw/lidar"],
            (std::vector<std::vector<std::byte>>{bytes({1, 2, 3}), bytes({4, 5})}));
  EXPECT_EQ(by_topic["/posed/raw/lidar/1"], (std::vector<std::vector<std::byte>>{bytes({9})}));

  const std::string effective = config::print_config(config);
  ASSERT_EQ(reader.channels().size(), 3u);
  for (const auto& [id, c] : reader.channels()) {
    EXPECT_EQ(c.metadata.at("posed.config"), effective) << c.topic;
    if (c.topic == "/posed/raw/imu") {
      EXPECT_EQ(c.metadata.at("posed.imu.source"), "serial");
      EXPECT_EQ(c.metadata.at("posed.imu.device"), "/dev/ttyA9");
      EXPECT_EQ(c.metadata.count("posed.lidar.address"), 0u);
    } else {
      EXPECT_EQ(c.metadata.at("posed.lidar.address"), "10.0.0.7") << c.topic;
      EXPECT_EQ(c.metadata.count("posed.imu.device"), 0u);
    }
  }
  std::filesystem::remove(path);
}

TEST(RecordingTap, CamerasCarryTheirDeviceAndFormatAndOtherStreamsTheConfigOnly) {
  config::PosedConfig config = config::default_config();
  config.thermal_camera.device = "/dev/v4l/by-id/usb-Guide-video-index0";
  config.thermal_camera.format = "y16";
  const auto thermal = recording_metadata(config, "thermal");
  EXPECT_EQ(thermal.at("posed.config"), config::print_config(config));
  EXPECT_EQ(thermal.at("posed.thermal.device"), config.thermal_camera.device);
  EXPECT_EQ(thermal.at("posed.thermal.format"), "y16");
  EXPECT_EQ(thermal.at("posed.thermal.source"), "v4l2");
  // The D435i's depth node is a camera like the others.
  config.depth_camera.device = "/dev/video2";
  const auto depth = recording_metadata(config, "depth");
  EXPECT_EQ(depth.at("posed.depth.device"), "/dev/video2");
  EXPECT_EQ(depth.at("posed.depth.format"), "z16");
  // A Source added later needs no change here: the configuration goes with it.
  const auto other = recording_metadata(config, "realsense_imu");
  EXPECT_EQ(other.size(), 1u);
  EXPECT_EQ(other.at("posed.config"), config::print_config(config));
}

}  // namespace recording_tap_test
}  // namespace posed::pipeline
