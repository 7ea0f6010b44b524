// Recorder -> MCAP -> McapReplaySource: the synthetic A9 source recorded and replayed gives the
// identical bytes and stamps; offsets, durations, loops, truncated files, drops, rotation, poses.

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "drivers/common/host_clock.hpp"
#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/mcap_replay_source.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "drivers/recording/recorder.hpp"
#include "drivers/recording/ros2_messages.hpp"
#include "drivers/synthetic/synthetic_imu_source.hpp"
#include "tests/unit/recording/temp_dir.hpp"

namespace posed::drivers::recording {
namespace {

struct Captured {
  std::vector<std::vector<std::byte>> bytes;
  std::vector<std::int64_t> stamps_ns;
};

/// Records `seconds` of the synthetic A9 (as fast as it generates) and returns what it read.
Captured record_synthetic(const std::string& path, double seconds, RecorderOptions opt = {}) {
  SyntheticImuConfig cfg;
  cfg.real_time = false;
  cfg.duration_s = seconds;
  cfg.rate_hz = 200;
  SyntheticImuSource src(cfg);
  std::string error;
  EXPECT_TRUE(src.open(error)) << error;
  Recorder rec;
  opt.writer.fsync_on_close = false;
  EXPECT_TRUE(rec.open(path, opt, error)) << error;
  const auto id = rec.add_raw_channel("imu", raw::kWireA9Serial, {{"config", "rate_hz: 200"}});
  EXPECT_NE(id, Recorder::kInvalidChannel);
  Captured c;
  RawChunk chunk;
  while (src.read(chunk, Duration::from_ms(100)) == ReadStatus::kData) {
    // The synthetic source stamps from 0 when not real time; shift so stamps look like a host.
    chunk.host_receive = chunk.host_receive + Duration::from_s(1000);
    c.bytes.emplace_back(chunk.bytes.begin(), chunk.bytes.end());
    c.stamps_ns.push_back(chunk.host_receive.ns);
    // The queue is large enough for a 2 s test; a drop here would be a bug.
    EXPECT_TRUE(rec.record(id, chunk));
  }
  EXPECT_TRUE(rec.close()) << rec.error();
  const auto counters = rec.counters();
  EXPECT_EQ(counters.messages_written, c.bytes.size());
  EXPECT_EQ(counters.dropped, 0u);
  return c;
}

McapReplayConfig cfg(const std::string& path, const std::string& stream, double rate,
                     bool loop = false, Duration start = Duration::from_ns(0),
                     Duration duration = Duration::from_ns(0)) {
  McapReplayConfig c;
  c.path = path;
  c.stream = stream;
  c.rate = rate;
  c.loop = loop;
  c.start_offset = start;
  c.duration = duration;
  return c;
}

/// The first half of the recording `name`, written to "cut.mcap" beside it: a recording whose
/// writer died mid-chunk. Returns its path.
std::string first_half(const test::TempDir& dir, const std::string& name) {
  const auto full = test::slurp(dir.file(name));
  test::spit(dir.file("cut.mcap"), std::span(full).subspan(0, full.size() / 2));
  return dir.file("cut.mcap");
}

Captured replay_all(McapReplaySource& src) {
  Captured c;
  RawChunk chunk;
  for (;;) {
    const auto s = src.read(chunk, Duration::from_ms(100));
    if (s == ReadStatus::kTimeout) continue;
    if (s != ReadStatus::kData) break;
    EXPECT_EQ(chunk.channel, 0u);
    c.bytes.emplace_back(chunk.bytes.begin(), chunk.bytes.end());
    c.stamps_ns.push_back(chunk.host_receive.ns);
  }
  return c;
}

TEST(RecordReplay, SyntheticA9BytesAndStampsAreIdentical) {
  test::TempDir dir("rec_a9");
  const std::string path = dir.file("a9.mcap");
  const auto recorded = record_synthetic(path, 2.0);
  ASSERT_GT(recorded.bytes.size(), 300u);

  for (int pass = 0; pass < 2; ++pass) {  // deterministic: twice the same
    McapReplaySource src(cfg(path, "imu", 0));
    std::string error;
    ASSERT_TRUE(src.open(error)) << error;
    EXPECT_FALSE(src.live());
    const auto replayed = replay_all(src);
    ASSERT_EQ(replayed.bytes.size(), recorded.bytes.size());
    EXPECT_EQ(replayed.bytes, recorded.bytes);
    EXPECT_EQ(replayed.stamps_ns, recorded.stamps_ns);
    EXPECT_TRUE(src.damage().empty()) << src.damage();
    const auto ch = src.channels();
    ASSERT_EQ(ch.size(), 1u);
    EXPECT_EQ(ch[0].wire_format, "a9-serial");
    EXPECT_EQ(ch[0].topic, "/posed/raw/imu");
    EXPECT_EQ(ch[0].metadata.at("config"), "rate_hz: 200");
    EXPECT_EQ(src.counters().chunks, recorded.bytes.size());
  }
}

TEST(RecordReplay, UnknownStreamIsAnOpenErrorNamingTheStreams) {
  test::TempDir dir("rec_unknown");
  record_synthetic(dir.file("a.mcap"), 0.1);
  McapReplaySource src(cfg(dir.file("a.mcap"), "lidar", 1));
  std::string error;
  EXPECT_FALSE(src.open(error));
  EXPECT_NE(error.find("'lidar'"), std::string::npos) << error;
  EXPECT_NE(error.find("imu"), std::string::npos) << error;
}

TEST(RecordReplay, StartOffsetAndDurationSelectAWindow) {
  test::TempDir dir("rec_window");
  const auto rec = record_synthetic(dir.file("w.mcap"), 2.0);
  McapReplaySource src(
      cfg(dir.file("w.mcap"), "imu", 0, false, Duration::from_ms(500), Duration::from_ms(1000)));
  std::string error;
  ASSERT_TRUE(src.open(error)) << error;
  const auto got = replay_all(src);
  const std::int64_t begin = rec.stamps_ns.front() + 500'000'000;
  std::vector<std::int64_t> want;
  for (auto t : rec.stamps_ns) {
    if (t >= begin && t <= begin + 1'000'000'000) want.push_back(t);
  }
  ASSERT_FALSE(want.empty());
  EXPECT_EQ(got.stamps_ns, want);
}

TEST(RecordReplay, LoopRepeatsTheBytesWithIncreasingStamps) {
  test::TempDir dir("rec_loop");
  const auto rec = record_synthetic(dir.file("l.mcap"), 0.2);
  McapReplaySource src(cfg(dir.file("l.mcap"), "imu", 0, true));
  std::string error;
  ASSERT_TRUE(src.open(error)) << error;
  RawChunk chunk;
  const std::size_t n = rec.bytes.size();
  std::int64_t last = 0;
  for (std::size_t i = 0; i < 3 * n; ++i) {
    ASSERT_EQ(src.read(chunk, Duration::from_ms(100)), ReadStatus::kData);
    ASSERT_EQ(chunk.bytes.size(), rec.bytes[i % n].size());
    EXPECT_EQ(std::memcmp(chunk.bytes.data(), rec.bytes[i % n].data(), chunk.bytes.size()), 0);
    EXPECT_GT(chunk.host_receive.ns, last) << "message " << i;
    last = chunk.host_receive.ns;
  }
  EXPECT_EQ(src.passes(), 2u);
  src.request_stop();
  EXPECT_EQ(src.read(chunk, Duration::from_ms(10)), ReadStatus::kEndOfStream);
}

TEST(RecordReplay, ATimeShiftMovesEveryStampAndTheDeliveredSpanIsRecordedTime) {
  // `posed --replay --loop` runs each pass through Sources of its own, shifted past the last.
  test::TempDir dir("rec_shift");
  const auto rec = record_synthetic(dir.file("s.mcap"), 0.2);
  McapReplayConfig c = cfg(dir.file("s.mcap"), "imu", 0);
  c.time_shift = Duration::from_seconds(7.5);
  McapReplaySource src(c);
  std::string error;
  ASSERT_TRUE(src.open(error)) << error;
  EXPECT_EQ(src.delivered_span().messages, 0u);
  const auto got = replay_all(src);
  ASSERT_EQ(got.stamps_ns.size(), rec.stamps_ns.size());
  for (std::size_t i = 0; i < got.stamps_ns.size(); ++i) {
    ASSERT_EQ(got.stamps_ns[i], rec.stamps_ns[i] + 7'500'000'000) << "message " << i;
  }
  const auto span = src.delivered_span();
  EXPECT_EQ(span.messages, rec.stamps_ns.size());
  EXPECT_EQ(span.first_log_ns, rec.stamps_ns.front());
  EXPECT_EQ(span.last_log_ns, rec.stamps_ns.back());
  EXPECT_EQ(span.last_gap_ns, rec.stamps_ns.back() - rec.stamps_ns[rec.stamps_ns.size() - 2]);
}

TEST(RecordReplay, OriginalTimingIsKeptScaledByTheRate) {
  test::TempDir dir("rec_rate");
  const auto rec = record_synthetic(dir.file("r.mcap"), 0.4);
  McapReplaySource src(cfg(dir.file("r.mcap"), "imu", 4.0));
  std::string error;
  ASSERT_TRUE(src.open(error)) << error;
  const HostTime t0 = host_now();
  const auto got = replay_all(src);
  const Duration took = host_now() - t0;
  EXPECT_EQ(got.bytes, rec.bytes);
  // The recording spans ~0.4 s; at 4x the replay cannot finish sooner than a quarter of it
  // (sleeps only ever run long; no upper bound, the machine may be busy).
  const std::int64_t span = rec.stamps_ns.back() - rec.stamps_ns.front();
  EXPECT_GE(took.ns, span / 4 - 1'000'000);
}

TEST(RecordReplay, ATruncatedRecordingReplaysUpToTheDamageAndSaysWhere) {
  test::TempDir dir("rec_cut");
  RecorderOptions opt;
  opt.writer.chunk_size_bytes = 4096;
  const auto rec = record_synthetic(dir.file("c.mcap"), 2.0, opt);
  McapReplaySource src(cfg(first_half(dir, "c.mcap"), "imu", 0));
  std::string error;
  ASSERT_TRUE(src.open(error)) << error;  // no summary: channels found while scanning
  const auto got = replay_all(src);
  ASSERT_GT(got.bytes.size(), 10u);
  ASSERT_LT(got.bytes.size(), rec.bytes.size());
  for (std::size_t i = 0; i < got.bytes.size(); ++i) ASSERT_EQ(got.bytes[i], rec.bytes[i]);
  EXPECT_NE(src.damage().find("offset"), std::string::npos) << src.damage();
}

// Paced replays read ahead on a thread of their own (posed's replays, replay_sources.cpp): what
// read() hands over must be what the Source read for itself, message for message.
TEST(RecordReplay, ReadingAheadDeliversTheSameBytesStampsAndDamage) {
  test::TempDir dir("rec_ahead");
  RecorderOptions opt;
  opt.writer.chunk_size_bytes = 4096;
  const auto rec = record_synthetic(dir.file("a.mcap"), 0.6, opt);
  first_half(dir, "a.mcap");
  for (const char* file : {"a.mcap", "cut.mcap"}) {
    McapReplaySource itself(cfg(dir.file(file), "imu", 0));
    McapReplayConfig c = cfg(dir.file(file), "imu", 20.0);
    c.read_ahead = Duration::from_ms(5);  // one message of 200 Hz at a time: the tightest window
    McapReplaySource ahead(c);
    std::string error;
    ASSERT_TRUE(itself.open(error)) << error;
    ASSERT_TRUE(ahead.open(error)) << error;
    const auto want = replay_all(itself);
    const auto got = replay_all(ahead);
    ASSERT_GT(want.bytes.size(), 10u) << file;
    EXPECT_EQ(got.bytes, want.bytes) << file;
    EXPECT_EQ(got.stamps_ns, want.stamps_ns) << file;
    EXPECT_EQ(ahead.damage(), itself.damage()) << file;
    EXPECT_EQ(ahead.delivered_span().messages, want.bytes.size()) << file;
    if (std::string(file) == "a.mcap") {
      EXPECT_EQ(got.bytes, rec.bytes);
    }
  }
}

TEST(RecordReplay, ReadingAheadLoopsAndStopsWhileTheReaderWaits) {
  test::TempDir dir("rec_ahead_loop");
  const auto rec = record_synthetic(dir.file("l.mcap"), 0.2);
  McapReplayConfig c = cfg(dir.file("l.mcap"), "imu", 50.0, true);
  c.read_ahead = Duration::from_ms(30);
  McapReplaySource src(c);
  std::string error;
  ASSERT_TRUE(src.open(error)) << error;
  RawChunk chunk;
  const std::size_t n = rec.bytes.size();
  std::int64_t last = 0;
  for (std::size_t i = 0; i < 3 * n;) {
    const auto status = src.read(chunk, Duration::from_ms(100));
    if (status == ReadStatus::kTimeout) continue;
    ASSERT_EQ(status, ReadStatus::kData) << "message " << i;
    ASSERT_EQ(chunk.bytes.size(), rec.bytes[i % n].size());
    EXPECT_EQ(std::memcmp(chunk.bytes.data(), rec.bytes[i % n].data(), chunk.bytes.size()), 0);
    EXPECT_GT(chunk.host_receive.ns, last) << "message " << i;
    last = chunk.host_receive.ns;
    ++i;
  }
  EXPECT_GE(src.passes(), 2u);
  // The reader is now waiting for room 30 ms ahead; a stop ends both sides (and the destructor
  // joins the reader: a hang here fails the test by its timeout).
  src.request_stop();
  EXPECT_EQ(src.read(chunk, Duration::from_ms(10)), ReadStatus::kEndOfStream);
}

TEST(RecordReplay, ReadingAheadCopiesImagesIntoBuffersItWasHandedBack) {
  // Images at 40 a second, each copied out of the file by the read-ahead thread: into the
  // buffers read() is done with, not fresh half-megabyte blocks each time.
  test::TempDir dir("rec_ahead_reuse");
  Recorder rec;
  RecorderOptions opt;
  opt.writer.fsync_on_close = false;
  std::string error;
  ASSERT_TRUE(rec.open(dir.file("i.mcap"), opt, error)) << error;
  const auto id = rec.add_raw_channel("visible", "yuyv");
  const int frames = 60;
  std::vector<std::byte> image(300u << 10);
  for (int i = 0; i < frames; ++i) {
    std::fill(image.begin(), image.end(), static_cast<std::byte>(i));
    ASSERT_TRUE(
        rec.record(id, RawChunk{image, HostTime::from_ns(1'000'000'000 + i * 2'000'000), 0}));
  }
  ASSERT_TRUE(rec.close()) << rec.error();
  McapReplayConfig c = cfg(dir.file("i.mcap"), "visible", 10.0);  // 500 frames a second
  c.read_ahead = Duration::from_ms(10);
  McapReplaySource src(c);
  ASSERT_TRUE(src.open(error)) << error;
  std::set<const std::byte*> buffers;
  RawChunk chunk;
  for (int i = 0; i < frames;) {
    const auto status = src.read(chunk, Duration::from_ms(100));
    if (status == ReadStatus::kTimeout) continue;
    ASSERT_EQ(status, ReadStatus::kData) << "frame " << i;
    ASSERT_EQ(chunk.bytes.size(), image.size());
    EXPECT_EQ(chunk.bytes.front(), static_cast<std::byte>(i));
    EXPECT_EQ(chunk.bytes.back(), static_cast<std::byte>(i));
    buffers.insert(chunk.bytes.data());
    ++i;
  }
  // Fresh buffers only while the reader fills its 10 ms window (5 frames) and whenever it reads
  // ahead faster than read() hands them back; most frames go into one handed back. Every
  // distinct buffer read() gave out was a fresh one: the reused ones are those handed back.
  // (How many fresh ones it takes depends on the scheduling: under ASan+UBSan beside a replay it
  // took 15 where a quiet machine takes at most 5 + 1 + kSpareBuffers, so that is not asserted.)
  EXPECT_GE(src.buffers_reused(), static_cast<std::uint64_t>(frames / 2));
  EXPECT_LE(buffers.size(), static_cast<std::size_t>(frames) - src.buffers_reused())
      << "distinct buffers over " << frames << " frames";
}

TEST(Recorder, DropsAreCountedAndEverythingAcceptedIsWritten) {
  test::TempDir dir("rec_drop");
  RecorderOptions opt;
  opt.queue_capacity = 4;  // tiny: the producer outruns the writer thread
  opt.writer.fsync_on_close = false;
  Recorder rec;
  std::string error;
  ASSERT_TRUE(rec.open(dir.file("d.mcap"), opt, error)) << error;
  const auto id = rec.add_raw_channel("lidar", raw::kWireVelodyneData);
  std::vector<std::byte> packet(1206, std::byte{7});
  std::uint64_t accepted = 0;
  const int attempts = 20000;
  for (int i = 0; i < attempts; ++i) {
    RawChunk c{packet, HostTime::from_ns(i * 1000), 0};
    if (rec.record(id, c)) ++accepted;
  }
  ASSERT_TRUE(rec.close());
  const auto counters = rec.counters();
  ASSERT_EQ(counters.channels.size(), 1u);
  EXPECT_EQ(counters.channels[0].recorded, accepted);
  EXPECT_EQ(counters.channels[0].dropped + accepted, static_cast<std::uint64_t>(attempts));
  EXPECT_EQ(counters.messages_written, accepted);
  McapReader r;
  ASSERT_TRUE(r.open(dir.file("d.mcap"), error)) << error;
  EXPECT_EQ(r.summary().message_count, accepted);
  // A bad id is refused, not a crash.
  EXPECT_FALSE(rec.record(77, RawChunk{packet, HostTime::from_ns(0), 0}));
}

TEST(Recorder, TheSameRawChannelAgainKeepsItsIdAndOneChannelRecord) {
  // A --loop pass taps fresh Sources of the same streams: one channel each in the file.
  test::TempDir dir("rec_same");
  Recorder rec;
  std::string error;
  ASSERT_TRUE(rec.open(dir.file("s.mcap"), RecorderOptions{}, error)) << error;
  const auto a = rec.add_raw_channel("imu", raw::kWireA9Serial, {{"config", "x"}});
  const auto b = rec.add_raw_channel("imu", raw::kWireA9Serial, {{"config", "x"}});
  const auto other = rec.add_raw_channel("imu", raw::kWireA9Serial, {{"config", "y"}});
  EXPECT_EQ(a, b);
  EXPECT_NE(a, other);
  std::vector<std::byte> bytes(16, std::byte{1});
  EXPECT_TRUE(rec.record(a, RawChunk{bytes, HostTime::from_ns(1), 0}));
  EXPECT_TRUE(rec.record(b, RawChunk{bytes, HostTime::from_ns(2), 0}));
  ASSERT_TRUE(rec.close());
  EXPECT_EQ(rec.counters().channels.size(), 2u);
  McapReader r;
  ASSERT_TRUE(r.open(dir.file("s.mcap"), error)) << error;
  EXPECT_EQ(r.channels().size(), 2u);
  EXPECT_EQ(r.summary().message_count, 2u);
}

TEST(Recorder, RotatesBySizeAndEveryFileIsComplete) {
  test::TempDir dir("rec_rotate");
  RecorderOptions opt;
  opt.rotate_bytes = 64 * 1024;
  opt.writer.chunk_size_bytes = 16 * 1024;
  opt.writer.compression = McapCompression::kNone;
  const auto rec = record_synthetic(dir.file("run.mcap"), 4.0, opt);
  std::uint64_t total = 0;
  std::size_t files = 0;
  for (std::size_t i = 0;; ++i) {
    const std::string name =
        i == 0 ? dir.file("run.mcap")
               : dir.file("run_" + std::string(i < 10 ? "00" : "0") + std::to_string(i) + ".mcap");
    if (!std::filesystem::exists(name)) break;
    ++files;
    McapReader r;
    std::string error;
    ASSERT_TRUE(r.open(name, error)) << error;
    McapMessage m;
    while (r.next(m)) ++total;
    EXPECT_TRUE(r.complete()) << name << ": " << r.stop_reason();
    EXPECT_TRUE(r.summary().usable()) << name;
    // every file describes its channel: replayable on its own
    ASSERT_EQ(r.channels().size(), 1u);
  }
  EXPECT_GE(files, 2u);
  EXPECT_EQ(total, rec.bytes.size());
}

TEST(Recorder, PosesAreRos2CdrWithRos2msgSchemas) {
  test::TempDir dir("rec_pose");
  RecorderOptions opt;
  opt.host_to_wall.wall_minus_host = Duration::from_s(1'700'000'000);
  opt.writer.fsync_on_close = false;
  Recorder rec;
  std::string error;
  ASSERT_TRUE(rec.open(dir.file("p.mcap"), opt, error)) << error;
  const WallTime stamp = WallTime::from_ns(1'700'000'123'456'789'012);
  ASSERT_TRUE(rec.write_pose("/posed/pose", stamp, "map", {1.5, -2.0, 0.25}, {0, 0, 0.6, 0.8}));
  ASSERT_TRUE(rec.write_odometry("/ground_truth", stamp, "map", "base_link", {3, 4, 5},
                                 {0, 0, 0, 1}, {1, 0, 0}, {0, 0, 0.1}));
  ASSERT_TRUE(rec.close());
  McapReader r;
  ASSERT_TRUE(r.open(dir.file("p.mcap"), error)) << error;
  McapMessage m;
  ASSERT_TRUE(r.next(m));
  EXPECT_EQ(m.channel->topic, "/posed/pose");
  EXPECT_EQ(m.channel->message_encoding, "cdr");
  ASSERT_NE(r.schema(m.channel->schema_id), nullptr);
  EXPECT_EQ(r.schema(m.channel->schema_id)->name, "geometry_msgs/msg/PoseStamped");
  EXPECT_EQ(r.schema(m.channel->schema_id)->encoding, "ros2msg");
  EXPECT_EQ(m.log_time_ns, 123'456'789'012u);  // on the host clock
  // Exact CDR bytes: header 00 01 00 00; sec, nanosec; frame "map" (len 4 incl. NUL), which
  // ends 8-aligned (payload offset 16), so the 7 doubles follow without padding.
  ASSERT_EQ(m.data.size(), 4u + 8 + 4 + 4 + 56);
  const std::uint8_t head[] = {0,    1,    0, 0, 0x7B, 0xF1, 0x53, 0x65, 0x14, 0x0C,
                               0x3A, 0x1B, 4, 0, 0,    0,    'm',  'a',  'p',  0};
  // 1'700'000'123 = 0x6553F17B; 456'789'012 = 0x1B3A0C14
  EXPECT_EQ(std::memcmp(m.data.data(), head, sizeof head), 0);
  double x = 0;
  std::memcpy(&x, m.data.data() + 4 + 16, 8);
  EXPECT_EQ(x, 1.5);
  ros2::StampedPose p;
  ASSERT_TRUE(ros2::decode_pose_stamped(m.data, p));
  EXPECT_EQ(p.stamp, stamp);
  EXPECT_EQ(p.frame_id, "map");
  EXPECT_EQ(p.p_xyz_m[1], -2.0);
  EXPECT_EQ(p.q_xyzw[3], 0.8);
  ASSERT_TRUE(r.next(m));
  EXPECT_EQ(r.schema(m.channel->schema_id)->name, "nav_msgs/msg/Odometry");
  // child "base_link" (u32 10 at payload 16, chars 20..30) pads to 32 before the doubles:
  // 4 + 32 + pose 56 + covariance 288 + twist 48 + covariance 288.
  EXPECT_EQ(m.data.size(), 4u + 32 + 56 + 288 + 48 + 288);
  std::memcpy(&x, m.data.data() + 4 + 32, 8);
  EXPECT_EQ(x, 3.0);
  std::string child;
  ASSERT_TRUE(ros2::decode_odometry(m.data, p, &child));
  EXPECT_EQ(child, "base_link");
  EXPECT_EQ(p.p_xyz_m[2], 5.0);
  EXPECT_FALSE(ros2::decode_pose_stamped(std::span(m.data).subspan(0, 10), p));
  // the host-to-wall offset is in the "posed" metadata record
  ASSERT_FALSE(r.metadata().empty());
  EXPECT_EQ(r.metadata()[0].entries.at("host_to_wall_ns"), "1700000000000000000");
}

TEST(Recorder, Ros2ChannelsCarryTheirSchemasInEveryRotatedFile) {
  test::TempDir dir("rec_ros2");
  RecorderOptions opt;
  opt.writer.fsync_on_close = false;
  opt.rotate_bytes = 1;  // every message closes its file: each later file must register again
  Recorder rec;
  std::string error;
  ASSERT_TRUE(rec.open(dir.file("r.mcap"), opt, error)) << error;
  EXPECT_EQ(rec.add_ros2_channel("/nope", "not_a/msg/Type"), Recorder::kInvalidChannel);
  const std::uint16_t tf = rec.add_ros2_channel("/tf", ros2::kTfMessageName);
  const std::uint16_t cloud = rec.add_ros2_channel("/posed/cloud", ros2::kPointCloud2Name, 2);
  ASSERT_NE(tf, Recorder::kInvalidChannel);
  ASSERT_NE(cloud, Recorder::kInvalidChannel);
  const std::vector<std::byte> body(40, std::byte{7});
  ASSERT_TRUE(rec.write_ros2(tf, WallTime::from_ns(1000), body));
  ASSERT_TRUE(rec.write_ros2(cloud, WallTime::from_ns(2000), body));
  ASSERT_TRUE(rec.write_ros2(tf, WallTime::from_ns(3000), body));
  EXPECT_FALSE(rec.write_ros2(Recorder::kInvalidChannel, WallTime::from_ns(4000), body));
  ASSERT_TRUE(rec.close());
  std::map<std::string, int> seen;
  for (const std::string& file : rec.files()) {
    McapReader r;
    ASSERT_TRUE(r.open(file, error)) << error;
    McapMessage m;
    while (r.next(m)) {
      const McapSchemaRecord* schema = r.schema(m.channel->schema_id);
      ASSERT_NE(schema, nullptr) << file;
      EXPECT_EQ(schema->encoding, "ros2msg");
      EXPECT_EQ(m.channel->message_encoding, "cdr");
      const std::string text(reinterpret_cast<const char*>(schema->data.data()),
                             schema->data.size());
      EXPECT_EQ(text, ros2::schema_for(schema->name));
      EXPECT_EQ(m.data.size(), body.size());
      ++seen[m.channel->topic + " " + schema->name];
    }
  }
  EXPECT_EQ(seen["/tf tf2_msgs/msg/TFMessage"], 2);
  EXPECT_EQ(seen["/posed/cloud sensor_msgs/msg/PointCloud2"], 1);
}

}  // namespace
}  // namespace posed::drivers::recording
