// HilPlaylist: which raw channels go out and where, log-time order restored across channels,
// --start/--duration/--loop, switching outputs off, recordings with nothing to send, and a file
// cut short.

#include <gtest/gtest.h>

#include <filesystem>

#include "tests/unit/hil/recording_builder.hpp"
#include "tools/hil/hil_playlist.hpp"

namespace posed::hil {
namespace playlist_test {

using test::RawMessage;

constexpr std::int64_t kT0 = 1'000'000'000'000;  // any host time [ns]
constexpr std::int64_t kMs = 1'000'000;

enum Ch : std::size_t { kImu = 0, kLidar = 1, kPosition = 2, kVisible = 3, kPose = 4 };

/// 100 ms of a rig: lidar every 1 ms, imu every 5 ms, a position packet every 50 ms, a camera
/// frame every 40 ms and a pose every 10 ms. The file order is the log-time order except that
/// every imu message is written after the lidar message 3 ms newer, as the Recorder's batches
/// can leave it.
std::vector<RawMessage> rig_messages() {
  std::vector<RawMessage> out;
  std::vector<RawMessage> held;
  for (std::uint32_t ms = 0; ms < 100; ++ms) {
    const std::int64_t t = kT0 + ms * kMs;
    out.push_back({kLidar, t, test::payload(kLidar, ms)});
    if (ms % 5 == 0) held.push_back({kImu, t + 100, test::payload(kImu, ms / 5)});
    if (ms % 50 == 0) out.push_back({kPosition, t + 200, test::payload(kPosition, ms / 50)});
    if (ms % 40 == 0) out.push_back({kVisible, t + 300, test::payload(kVisible, ms / 40, 64)});
    if (ms % 10 == 0) out.push_back({kPose, t + 400, test::payload(kPose, ms / 10)});
    for (auto it = held.begin(); it != held.end();) {
      if (it->log_ns + 3 * kMs <= t) {
        out.push_back(*it);
        it = held.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (auto& h : held) out.push_back(h);
  return out;
}

std::vector<HilMessage> read_all(HilPlaylist& p, std::size_t limit = 100000) {
  std::vector<HilMessage> out;
  HilMessage m;
  while (out.size() < limit && p.next(m)) out.push_back(m);
  return out;
}

class Playlist : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    ASSERT_TRUE(test::write_recording(path_, test::rig_channels(), rig_messages(), error,
                                      /*host_to_wall_ns=*/123'456'789))
        << error;
  }
  HilPlaylistOptions options() const {
    HilPlaylistOptions o;
    o.path = path_;
    return o;
  }
  test::TempDir dir_{"playlist"};
  std::string path_ = dir_.file("rig.mcap");
};

TEST_F(Playlist, SendsLidarAndImuInLogTimeOrderAndListsTheRest) {
  HilPlaylist p;
  std::string error;
  ASSERT_TRUE(p.open(options(), error)) << error;
  ASSERT_EQ(p.channels().size(), 4u);  // the raw ones; the pose topic is not raw data
  for (const HilChannel& c : p.channels()) {
    if (c.wire_format == "yuyv") {
      EXPECT_FALSE(c.sent);
      EXPECT_EQ(c.output, HilOutput::kNone);
    } else {
      EXPECT_TRUE(c.sent) << c.topic;
    }
  }
  const auto got = read_all(p);
  ASSERT_EQ(got.size(), 100u + 20u + 2u);
  std::size_t lidar = 0, imu = 0, position = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    if (i > 0) {
      EXPECT_LE(got[i - 1].log_ns, got[i].log_ns) << "message " << i;
    }
    const HilChannel& c = p.channels()[got[i].channel];
    EXPECT_EQ(got[i].output, c.output);
    switch (got[i].output) {
      case HilOutput::kUdpData:
        EXPECT_EQ(got[i].bytes, test::payload(kLidar, static_cast<std::uint32_t>(lidar++)));
        break;
      case HilOutput::kSerial:
        EXPECT_EQ(got[i].bytes, test::payload(kImu, static_cast<std::uint32_t>(imu++)));
        break;
      case HilOutput::kUdpPosition:
        EXPECT_EQ(got[i].bytes, test::payload(kPosition, static_cast<std::uint32_t>(position++)));
        EXPECT_EQ(c.source_channel, 1u);
        break;
      case HilOutput::kNone:
      case HilOutput::kIio:  // the recording has no D435i IMU
        ADD_FAILURE() << "a channel without output was sent";
    }
  }
  EXPECT_EQ(p.begin_log_ns(), kT0);
  EXPECT_EQ(p.end_log_ns(), kT0 + 99 * kMs);  // the summary's last message (lidar)
  HostToWall h2w{};
  ASSERT_TRUE(p.recorded_host_to_wall(h2w));
  EXPECT_EQ(h2w.wall_minus_host.ns, 123'456'789);
  EXPECT_TRUE(p.damage().empty()) << p.damage();
}

TEST_F(Playlist, StartAndDurationSelectAWindowOfLogTime) {
  HilPlaylistOptions o = options();
  o.start = Duration::from_ms(20);
  o.duration = Duration::from_ms(30);
  HilPlaylist p;
  std::string error;
  ASSERT_TRUE(p.open(o, error)) << error;
  const auto got = read_all(p);
  ASSERT_FALSE(got.empty());
  for (const auto& m : got) {
    EXPECT_GE(m.log_ns, kT0 + 20 * kMs);
    EXPECT_LE(m.log_ns, kT0 + 50 * kMs);
  }
  // lidar 20..50 ms (31), imu at 20, 25, ... 45 ms (+0.1 ms: 6), position at 50.2 ms is past it.
  std::size_t lidar = 0, imu = 0;
  for (const auto& m : got) {
    lidar += m.output == HilOutput::kUdpData;
    imu += m.output == HilOutput::kSerial;
  }
  EXPECT_EQ(lidar, 31u);
  EXPECT_EQ(imu, 6u);
}

TEST_F(Playlist, LoopRepeatsTheBytesWithLogTimesMovingForward) {
  HilPlaylistOptions o = options();
  o.loop = true;
  HilPlaylist p;
  std::string error;
  ASSERT_TRUE(p.open(o, error)) << error;
  const auto got = read_all(p, 3 * 122);
  ASSERT_EQ(got.size(), 3u * 122u);
  EXPECT_GE(p.passes(), 2u);
  for (std::size_t i = 1; i < got.size(); ++i) EXPECT_LE(got[i - 1].log_ns, got[i].log_ns) << i;
  for (std::size_t i = 0; i < 122; ++i) {
    EXPECT_EQ(got[i].bytes, got[i + 122].bytes) << i;
    EXPECT_EQ(got[i].bytes, got[i + 244].bytes) << i;
    // Every pass is shifted by the same amount (its span plus one gap).
    EXPECT_EQ(got[i + 122].log_ns - got[i].log_ns, got[i + 244].log_ns - got[i + 122].log_ns);
  }
  EXPECT_GT(got[122].log_ns, got[121].log_ns);
}

TEST_F(Playlist, OutputsCanBeSwitchedOff) {
  for (const bool udp : {false, true}) {
    HilPlaylistOptions o = options();
    o.udp = udp;
    o.serial = !udp;
    HilPlaylist p;
    std::string error;
    ASSERT_TRUE(p.open(o, error)) << error;
    for (const auto& m : read_all(p)) {
      EXPECT_EQ(m.output == HilOutput::kSerial, !udp);
    }
  }
  HilPlaylistOptions none = options();
  none.udp = none.serial = false;
  HilPlaylist p;
  std::string error;
  EXPECT_FALSE(p.open(none, error));
  EXPECT_NE(error.find("no raw channel to re-emit"), std::string::npos) << error;
}

TEST(PlaylistBadInput, ARecordingWithNothingToSendNamesItsFormats) {
  test::TempDir dir("nothing");
  std::string error;
  ASSERT_TRUE(test::write_recording(dir.file("cam.mcap"), {{"visible", "yuyv", 0, false}},
                                    {{0, kT0, test::payload(0, 0, 64)}}, error))
      << error;
  HilPlaylistOptions o;
  o.path = dir.file("cam.mcap");
  HilPlaylist p;
  EXPECT_FALSE(p.open(o, error));
  EXPECT_NE(error.find("yuyv"), std::string::npos) << error;
  EXPECT_NE(error.find("cam.mcap"), std::string::npos) << error;
}

TEST(PlaylistBadInput, NotAnMcapFileIsAnOpenError) {
  test::TempDir dir("notmcap");
  const std::string path = dir.file("x.mcap");
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  std::fputs("not a recording", f);
  std::fclose(f);
  HilPlaylistOptions o;
  o.path = path;
  HilPlaylist p;
  std::string error;
  EXPECT_FALSE(p.open(o, error));
  EXPECT_NE(error.find("not an MCAP file"), std::string::npos) << error;
}

TEST(PlaylistBadInput, AFileCutShortPlaysUpToTheDamageAndSaysWhere) {
  test::TempDir dir("cut");
  const std::string path = dir.file("cut.mcap");
  std::string error;
  ASSERT_TRUE(test::write_recording(path, test::rig_channels(), rig_messages(), error, 0, 1024))
      << error;
  const auto full = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, full / 2);
  HilPlaylistOptions o;
  o.path = path;
  HilPlaylist p;
  ASSERT_TRUE(p.open(o, error)) << error;
  const auto got = read_all(p);
  EXPECT_GT(got.size(), 10u);
  EXPECT_LT(got.size(), 122u);
  for (std::size_t i = 1; i < got.size(); ++i) EXPECT_LE(got[i - 1].log_ns, got[i].log_ns);
  EXPECT_NE(p.damage().find("offset"), std::string::npos) << p.damage();
}

}  // namespace playlist_test
}  // namespace posed::hil
