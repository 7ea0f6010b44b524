// posectl import as a user runs it: a real Velodyne pcap becomes the raw channels `posed --record`
// writes (and a replay Source delivers the capture's payloads with their capture times), a
// candump log becomes /posed/raw/imu, ROS 1 bags keep every connection with the topic map
// applied, and inputs that are none of these, or damaged, are named.

#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <set>

#include "drivers/recording/mapped_file.hpp"
#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/mcap_replay_source.hpp"
#include "drivers/recording/pcap_parser.hpp"
#include "drivers/recording/pcap_udp.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "tests/common/realdata.hpp"
#include "tests/common/ros1_bag_writer.hpp"
#include "tests/common/ros1_serialize.hpp"
#include "tests/integration/posed_process.hpp"

namespace posed::testing {
namespace import_test {

using namespace std::chrono_literals;
namespace rec = drivers::recording;
namespace ser = test::ros1;

std::string posectl() { return build_dir() + "/tools/posectl/posectl"; }

struct ImportRun {
  int rc;
  std::string out, err;
};
ImportRun run_import(const TempDir& dir, std::vector<std::string> args) {
  args.insert(args.begin(), {posectl(), "import"});
  PosedProcess p(args, {}, dir);
  const int rc = p.wait_for_exit(60s).value_or(-1);
  return {rc, p.out(), p.err()};
}

std::map<std::string, rec::McapChannelRecord> channels_by_topic(const rec::McapReader& reader) {
  std::map<std::string, rec::McapChannelRecord> out;
  for (const auto& [id, c] : reader.channels()) out[c.topic] = c;
  return out;
}

/// A value of the recording's "posed" Metadata record (read by a scan, as replay_sources does).
std::string metadata_value(const std::string& path, const std::string& key) {
  rec::McapReader reader;
  std::string error;
  EXPECT_TRUE(reader.open(path, error)) << error;
  rec::McapMessage message;
  while (reader.next(message)) {
  }
  for (const auto& m : reader.metadata()) {
    if (m.name == rec::raw::kMetadataName && m.entries.count(key)) return m.entries.at(key);
  }
  return "(absent)";
}

TEST(Import, AVelodynePcapBecomesTheRawChannelsPosedRecordWrites) {
  POSED_REQUIRE_REALDATA(pcap, "velodyne_vlp32c/vlp32c_nebula_5scans.pcap");
  // What the capture holds, counted with the pcap reader itself.
  rec::MappedFile file;
  std::string error;
  ASSERT_TRUE(file.open(pcap, error, "pcap")) << error;
  rec::PcapParser parser(file.bytes());
  ASSERT_EQ(parser.open(), rec::PcapStatus::kOk);
  std::vector<std::pair<std::int64_t, std::vector<std::byte>>> data_port;
  rec::PcapRecord record;
  while (parser.next(record) == rec::PcapStatus::kOk) {
    rec::UdpDatagram d;
    if (rec::extract_udp(record.link_type, record.frame, d) == rec::FrameStatus::kOk &&
        d.dst_port == 2368) {
      data_port.emplace_back(record.timestamp_ns,
                             std::vector<std::byte>(d.payload.begin(), d.payload.end()));
    }
  }
  ASSERT_FALSE(data_port.empty());

  TempDir dir;
  const std::string out = dir.file("capture.mcap");
  const ImportRun r = run_import(dir, {pcap, "-o", out});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("pcap capture"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(std::to_string(data_port.size()) + " messages"), std::string::npos) << r.out;

  rec::McapReader reader;
  ASSERT_TRUE(reader.open(out, error)) << error;
  EXPECT_TRUE(reader.summary().usable());
  const auto channels = channels_by_topic(reader);
  ASSERT_TRUE(channels.count("/posed/raw/lidar"));
  const rec::McapChannelRecord& c = channels.at("/posed/raw/lidar");
  EXPECT_EQ(c.message_encoding, rec::raw::kMessageEncoding);
  EXPECT_EQ(c.schema_id, 0);
  EXPECT_EQ(c.metadata.at(std::string(rec::raw::kStreamKey)), "lidar");
  EXPECT_EQ(c.metadata.at(std::string(rec::raw::kWireFormatKey)), rec::raw::kWireVelodyneData);
  EXPECT_EQ(c.metadata.at(std::string(rec::raw::kSourceChannelKey)), "0");
  EXPECT_EQ(metadata_value(out, std::string(rec::raw::kHostToWallKey)), "0");

  // The replay Source posed uses gives back every payload with its capture time.
  rec::McapReplayConfig config;
  config.path = out;
  config.stream = "lidar";
  config.rate = 0;
  rec::McapReplaySource source(config);
  ASSERT_TRUE(source.open(error)) << error;
  drivers::RawChunk chunk;
  std::size_t i = 0;
  while (source.read(chunk, Duration::from_ms(10)) == drivers::ReadStatus::kData) {
    ASSERT_LT(i, data_port.size());
    EXPECT_EQ(chunk.host_receive.ns, data_port[i].first) << i;
    EXPECT_EQ(chunk.channel, 0u);
    ASSERT_EQ(chunk.bytes.size(), data_port[i].second.size());
    EXPECT_EQ(std::memcmp(chunk.bytes.data(), data_port[i].second.data(), chunk.bytes.size()), 0);
    ++i;
  }
  EXPECT_EQ(i, data_port.size());
  EXPECT_EQ(source.wire_format(0), rec::raw::kWireVelodyneData);

  // Another data port: nothing of this capture is lidar data any more, and the summary says why.
  const ImportRun other =
      run_import(dir, {pcap, "-o", dir.file("other.mcap"), "--data-port", "2370"});
  ASSERT_EQ(other.rc, 0) << other.err;
  EXPECT_NE(other.out.find("0 messages"), std::string::npos) << other.out;
  EXPECT_NE(other.out.find("to other ports than 2370/8308 left out"), std::string::npos)
      << other.out;
}

TEST(Import, ACandumpLogBecomesTheRawImuStream) {
  TempDir dir;
  const std::string log = dir.write("imu.log",
                                    "(1600000000.000100) can0 181#0102030405060708\n"
                                    "(1600000000.010100) can0 182#0A0B\n"
                                    "(1600000000.020100) can0 181#1112131415161718\n");
  const std::string out = dir.file("can.mcap");
  const ImportRun r = run_import(dir, {log, "-o", out});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("candump log"), std::string::npos) << r.out;
  rec::McapReader reader;
  std::string error;
  ASSERT_TRUE(reader.open(out, error)) << error;
  const auto channels = channels_by_topic(reader);
  ASSERT_TRUE(channels.count("/posed/raw/imu"));
  EXPECT_EQ(channels.at("/posed/raw/imu").metadata.at(std::string(rec::raw::kWireFormatKey)),
            rec::raw::kWireCanFrame);
  rec::McapMessage m;
  std::vector<std::uint64_t> times;
  while (reader.next(m)) {
    times.push_back(m.log_time_ns);
    EXPECT_EQ(m.data.size(), 16u) << "struct can_frame";
  }
  EXPECT_EQ(times,
            (std::vector<std::uint64_t>{1'600'000'000'000'100'000ull, 1'600'000'000'010'100'000ull,
                                        1'600'000'000'020'100'000ull}));
}

TEST(Import, AnUnknownInputIsNamedWithItsFirstBytes) {
  TempDir dir;
  const std::string in = dir.write("notes.txt", "hello, not a capture\n");
  const ImportRun r = run_import(dir, {in, "-o", dir.file("x.mcap")});
  EXPECT_EQ(r.rc, 1);
  EXPECT_NE(r.err.find(in + ": not a recognised input"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("68 65 6c 6c 6f"), std::string::npos) << r.err;  // "hello"
  EXPECT_NE(r.err.find("\"hello, not a cap"), std::string::npos) << r.err;
}

/// A bag with a renamed IMU topic, the default lidar topic, a topic without a header and a
/// connection that never publishes.
test::Ros1BagWriter small_bag() {
  test::Ros1BagWriter w(test::Ros1BagWriter::Options::with(test::Ros1BagWriter::Compression::kBz2));
  const auto imu = w.add_connection("/my_robot/imu", "sensor_msgs/Imu", std::string(ser::kImuMd5),
                                    ser::kImuDefinition, "/imu_driver");
  const auto imu_default = w.add_connection("/handsfree/imu", "sensor_msgs/Imu",
                                            std::string(ser::kImuMd5), ser::kImuDefinition);
  const auto note = w.add_connection("/notes", "std_msgs/String", std::string(ser::kStringMd5),
                                     std::string(ser::kStringDefinition), "", true);
  w.add_connection("/silent", "std_msgs/String", std::string(ser::kStringMd5),
                   std::string(ser::kStringDefinition));
  const std::uint64_t t0 = 1'600'000'000'000'000'000ull;
  for (std::uint32_t i = 0; i < 20; ++i) {
    const std::uint64_t t = t0 + i * 5'000'000ull;
    // Stamped 1 ms before it was received.
    w.write(imu, t, ser::imu(i, static_cast<std::int64_t>(t - 1'000'000), "imu", {}));
    w.write(imu_default, t + 1, ser::imu(i, static_cast<std::int64_t>(t), "imu", {}));
  }
  ser::Serializer s;
  s.string("hello");
  w.write(note, t0 + 7, s.bytes);
  w.close();
  return w;
}

TEST(Import, BagsKeepEveryConnectionAndTheTopicMapDecidesTheStreams) {
  TempDir dir;
  const std::string bag = dir.file("small.bag");
  small_bag().save(bag);
  const std::string out = dir.file("small.mcap");
  const ImportRun r = run_import(
      dir, {bag, "-o", out, "--topic-map", "/my_robot/imu=imu", "--topic-map", "/handsfree/imu="});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("41 messages on 4 channels"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("posed streams: imu\n"), std::string::npos) << r.out;

  rec::McapReader reader;
  std::string error;
  ASSERT_TRUE(reader.open(out, error)) << error;
  const auto channels = channels_by_topic(reader);
  ASSERT_EQ(channels.size(), 4u);
  const auto& mapped = channels.at("/my_robot/imu");
  EXPECT_EQ(mapped.message_encoding, "ros1");
  EXPECT_EQ(mapped.metadata.at("posed.stream"), "imu");
  EXPECT_EQ(mapped.metadata.at("posed.wire_format"), "ros1:sensor_msgs/Imu");
  EXPECT_EQ(mapped.metadata.at("callerid"), "/imu_driver");
  EXPECT_EQ(channels.at("/handsfree/imu").metadata.count("posed.stream"), 0u) << "unmapped";
  EXPECT_EQ(channels.at("/notes").metadata.at("latching"), "true");
  EXPECT_TRUE(channels.count("/silent")) << "a connection without messages is kept";
  // Both IMU topics share one schema (same type and definition).
  EXPECT_EQ(mapped.schema_id, channels.at("/handsfree/imu").schema_id);
  EXPECT_EQ(reader.schema(channels.at("/notes").schema_id)->name, "std_msgs/String");
  rec::McapMessage m;
  std::size_t imu = 0;
  while (reader.next(m)) {
    if (m.channel->topic == "/my_robot/imu") {
      ++imu;
      EXPECT_EQ(m.log_time_ns - m.publish_time_ns, 1'000'000u) << "publish time = header.stamp";
    } else if (m.channel->topic == "/notes") {
      EXPECT_EQ(m.publish_time_ns, m.log_time_ns) << "no header: publish time = receive time";
    }
  }
  EXPECT_EQ(imu, 20u);
  EXPECT_EQ(metadata_value(out, std::string(rec::raw::kHostToWallKey)), "0");

  const ImportRun bad = run_import(dir, {bag, "-o", dir.file("y.mcap"), "--topic-map", "imu"});
  EXPECT_EQ(bad.rc, 2);
  EXPECT_NE(bad.err.find("expected TOPIC=STREAM"), std::string::npos) << bad.err;
}

TEST(Import, ADamagedBagImportsWhatIsReadableAndSaysWhere) {
  TempDir dir;
  const test::Ros1BagWriter w = small_bag();
  std::vector<std::byte> cut = w.bytes();
  const std::uint64_t chunk = w.chunk_offsets().front();
  cut.resize(static_cast<std::size_t>(chunk + 100));  // inside the only chunk
  const std::string bag = dir.file("cut.bag");
  {
    std::ofstream f(bag, std::ios::binary);
    f.write(reinterpret_cast<const char*>(cut.data()), static_cast<std::streamsize>(cut.size()));
  }
  const ImportRun r = run_import(dir, {bag, "-o", dir.file("cut.mcap")});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("0 messages"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("warning: reading stopped early: truncated Chunk record at offset " +
                       std::to_string(chunk)),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("read sequentially"), std::string::npos) << r.out;
}

}  // namespace import_test
}  // namespace posed::testing
