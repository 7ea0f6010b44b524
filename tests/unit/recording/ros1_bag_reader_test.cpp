// The ROS 1 bag reader against bags written by the test writer (tests/common/ros1_bag_writer.hpp):
// round trips through every chunk compression, indexed and sequential reading, and bad input:
// wrong magic, truncation at many offsets, unknown compression, unknown op, corrupt chunk data,
// messages on undefined connections.

#include "drivers/recording/ros1_bag_reader.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "tests/common/ros1_bag_writer.hpp"

namespace posed::testing {
namespace ros1_bag_reader_test {

namespace ros1 = drivers::recording::ros1;
using test::Ros1BagWriter;

std::vector<std::byte> payload(std::uint32_t conn, std::uint32_t i) {
  // Sizes vary so records straddle chunk thresholds differently.
  std::vector<std::byte> b(8 + (i * 37 + conn * 11) % 300);
  std::memcpy(b.data(), &conn, 4);
  std::memcpy(b.data() + 4, &i, 4);
  for (std::size_t k = 8; k < b.size(); ++k) b[k] = static_cast<std::byte>((k * 7 + i) & 0xff);
  return b;
}

ros1::BagReaderOptions reader_options(bool use_index) {
  ros1::BagReaderOptions o;
  o.use_index = use_index;
  return o;
}

struct Written {
  std::uint64_t time_ns;
  std::uint32_t conn;
  std::vector<std::byte> data;
};

/// Three connections, `n` messages each at 100/50/10 Hz-like interleaving, small chunks.
Ros1BagWriter make_bag(Ros1BagWriter::Options options, std::uint32_t n,
                       std::vector<Written>& written) {
  Ros1BagWriter w(options);
  const std::uint32_t imu = w.add_connection("/handsfree/imu", "sensor_msgs/Imu", "imu-md5",
                                             "Header header\nfloat64 x\n", "/imu_node");
  const std::uint32_t pts = w.add_connection("/velodyne_points", "sensor_msgs/PointCloud2",
                                             "pc-md5", "Header header\n", "/velodyne");
  const std::uint32_t tf = w.add_connection("/tf_static", "tf2_msgs/TFMessage", "tf-md5",
                                            "geometry_msgs/TransformStamped[] transforms\n", "",
                                            /*latching=*/true);
  const std::uint64_t t0 = 1'628'000'000'000'000'000ull;
  for (std::uint32_t i = 0; i < n; ++i) {
    for (const std::uint32_t c : {imu, pts, tf}) {
      if (c == pts && i % 2 != 0) continue;
      if (c == tf && i % 10 != 0) continue;
      const std::uint64_t t = t0 + i * 10'000'000ull + c * 1'000ull;
      written.push_back({t, c, payload(c, i)});
      w.write(c, t, written.back().data);
    }
  }
  w.close();
  return w;
}

std::vector<Written> read_all(ros1::BagReader& reader) {
  std::vector<Written> out;
  ros1::BagMessage m;
  while (reader.next(m)) {
    out.push_back({m.receive_time_ns, m.connection->id, {m.data.begin(), m.data.end()}});
  }
  return out;
}

bool same(const Written& a, const Written& b) {
  return a.time_ns == b.time_ns && a.conn == b.conn && a.data == b.data;
}

class BagRoundTrip : public ::testing::TestWithParam<Ros1BagWriter::Compression> {};

TEST_P(BagRoundTrip, EveryMessageComesBackInReceiveTimeOrderIndexedAndSequentially) {
  std::vector<Written> written;
  const Ros1BagWriter w = make_bag(Ros1BagWriter::Options::with(GetParam(), 4096), 400, written);
  ASSERT_GT(w.chunk_offsets().size(), 10u) << "small chunks, so many of them";

  for (const bool use_index : {true, false}) {
    SCOPED_TRACE(use_index ? "indexed" : "sequential");
    ros1::BagReader reader;
    std::string error;
    ASSERT_TRUE(reader.open_bytes(w.bytes(), error, reader_options(use_index))) << error;
    EXPECT_EQ(reader.indexed(), use_index);
    const std::vector<Written> got = read_all(reader);
    EXPECT_TRUE(reader.complete())
        << reader.stop_reason() << (reader.issues().empty() ? "" : reader.issues()[0].what);
    EXPECT_TRUE(reader.stop_reason().empty());
    ASSERT_EQ(got.size(), written.size());
    // Written in time order, so both ways give exactly the written sequence.
    for (std::size_t i = 0; i < got.size(); ++i) {
      ASSERT_TRUE(same(got[i], written[i])) << "message " << i;
    }
    ASSERT_EQ(reader.connections().size(), 3u);
    const ros1::BagConnection& imu = reader.connections().at(0);
    EXPECT_EQ(imu.topic, "/handsfree/imu");
    EXPECT_EQ(imu.type, "sensor_msgs/Imu");
    EXPECT_EQ(imu.md5sum, "imu-md5");
    EXPECT_EQ(imu.message_definition, "Header header\nfloat64 x\n");
    EXPECT_EQ(imu.callerid, "/imu_node");
    EXPECT_FALSE(imu.latching);
    EXPECT_TRUE(reader.connections().at(2).latching);
    EXPECT_EQ(reader.chunks().size(), w.chunk_offsets().size());
    EXPECT_EQ(reader.counters().chunks, w.chunk_offsets().size());
    if (use_index) {
      std::map<std::uint32_t, std::uint64_t> expected;
      for (const Written& x : written) ++expected[x.conn];
      EXPECT_EQ(reader.indexed_counts(), expected);
      EXPECT_EQ(reader.header_chunk_count(), w.chunk_offsets().size());
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Compressions, BagRoundTrip,
                         ::testing::Values(Ros1BagWriter::Compression::kNone,
                                           Ros1BagWriter::Compression::kBz2,
                                           Ros1BagWriter::Compression::kLz4),
                         [](const auto& param_info) {
                           switch (param_info.param) {
                             case Ros1BagWriter::Compression::kNone:
                               return std::string("none");
                             case Ros1BagWriter::Compression::kBz2:
                               return std::string("bz2");
                             case Ros1BagWriter::Compression::kLz4:
                               return std::string("lz4");
                           }
                           return std::string("unknown");
                         });

TEST(BagReader, TheIndexMergesChunksThatOverlapInTime) {
  // A late message (sent at t=20, received after t=30 was written) lands in the next chunk;
  // the index puts it back in receive-time order, a scan delivers chunk by chunk.
  Ros1BagWriter w(Ros1BagWriter::Options::with(Ros1BagWriter::Compression::kLz4, 1));
  const std::uint32_t c = w.add_connection("/a", "std_msgs/UInt32", "md5", "uint32 data\n");
  for (const std::uint64_t t : {10u, 30u, 20u, 40u}) {
    const std::uint32_t v = static_cast<std::uint32_t>(t);
    std::vector<std::byte> b(4);
    std::memcpy(b.data(), &v, 4);
    w.write(c, t, b);
  }
  w.close();
  for (const bool use_index : {true, false}) {
    ros1::BagReader reader;
    std::string error;
    ASSERT_TRUE(reader.open_bytes(w.bytes(), error, reader_options(use_index))) << error;
    std::vector<std::uint64_t> times;
    for (const Written& x : read_all(reader)) times.push_back(x.time_ns);
    if (use_index) {
      EXPECT_EQ(times, (std::vector<std::uint64_t>{10, 20, 30, 40}));
    } else {
      EXPECT_EQ(times, (std::vector<std::uint64_t>{10, 30, 20, 40}));
    }
  }
}

TEST(BagReader, ABagThatWasNeverClosedIsReadSequentiallyAndSaysSo) {
  std::vector<Written> written;
  const Ros1BagWriter w = make_bag(
      Ros1BagWriter::Options::with(Ros1BagWriter::Compression::kBz2, 8192, false), 100, written);
  ros1::BagReader reader;
  std::string error;
  ASSERT_TRUE(reader.open_bytes(w.bytes(), error)) << error;
  EXPECT_FALSE(reader.indexed());
  ASSERT_FALSE(reader.issues().empty());
  EXPECT_NE(reader.issues()[0].what.find("index_pos is 0"), std::string::npos)
      << reader.issues()[0].what;
  EXPECT_EQ(reader.issues()[0].offset, 13u);
  EXPECT_EQ(read_all(reader).size(), written.size());
  EXPECT_EQ(reader.connections().size(), 3u);
}

TEST(BagReader, WrongMagicAndOtherVersionsAreOpenErrorsNamingOffsetZero) {
  const auto bytes = [](std::string_view s) {
    std::vector<std::byte> b(s.size());
    std::memcpy(b.data(), s.data(), s.size());
    return b;
  };
  ros1::BagReader reader;
  std::string error;
  EXPECT_FALSE(reader.open_bytes(bytes("\x89HDF\r\n\x1a\n and more bytes"), error));
  EXPECT_NE(error.find("wrong magic at offset 0"), std::string::npos) << error;
  EXPECT_NE(error.find("\\x89HDF"), std::string::npos) << error;
  ros1::BagReader old;
  EXPECT_FALSE(old.open_bytes(bytes("#ROSRECORD V1.2\nop=..."), error));
  EXPECT_NE(error.find("unsupported bag format version"), std::string::npos) << error;
  ros1::BagReader empty;
  EXPECT_FALSE(empty.open_bytes({}, error));
  EXPECT_NE(error.find("wrong magic"), std::string::npos) << error;
}

TEST(BagReader, ABagCutAtAnyOffsetReadsUpToTheDamageAndSaysWhere) {
  std::vector<Written> written;
  const Ros1BagWriter w =
      make_bag(Ros1BagWriter::Options::with(Ros1BagWriter::Compression::kLz4, 2048), 60, written);
  const std::vector<std::byte>& full = w.bytes();
  const std::vector<std::uint64_t> chunks = w.chunk_offsets();
  const std::vector<std::uint64_t> counts = w.chunk_message_counts();
  std::vector<std::size_t> cuts;
  for (std::size_t cut = 0; cut < full.size(); cut += 61) cuts.push_back(cut);
  for (const std::uint64_t c : chunks) {
    for (const std::int64_t d : {-9, -8, -4, -1, 0, 1, 4, 8, 40}) {
      const std::int64_t cut = static_cast<std::int64_t>(c) + d;
      if (cut > 0 && cut < static_cast<std::int64_t>(full.size())) {
        cuts.push_back(static_cast<std::size_t>(cut));
      }
    }
  }
  for (const std::size_t cut : cuts) {
    SCOPED_TRACE("cut at " + std::to_string(cut));
    const std::vector<std::byte> prefix(full.begin(),
                                        full.begin() + static_cast<std::ptrdiff_t>(cut));
    ros1::BagReader reader;
    std::string error;
    if (!reader.open_bytes(prefix, error)) {
      // Only a cut inside the magic line makes it not a bag at all.
      EXPECT_LT(cut, 13u) << error;
      continue;
    }
    const std::vector<Written> got = read_all(reader);
    EXPECT_FALSE(reader.complete());
    EXPECT_FALSE(reader.indexed()) << "the index lies past every cut";
    ASSERT_LE(got.size(), written.size());
    for (std::size_t i = 0; i < got.size(); ++i) ASSERT_TRUE(same(got[i], written[i])) << i;
    // Every chunk followed by another that starts before the cut is whole, so delivered.
    std::size_t expected_min = 0;
    for (std::size_t k = 0; k + 1 < chunks.size(); ++k) {
      if (chunks[k + 1] <= cut) expected_min += counts[k];
    }
    EXPECT_GE(got.size(), expected_min);
    if (cut > 13) {
      // Where reading stopped is named by its offset: the record it cut, or the clean end of the
      // records before the missing index.
      EXPECT_NE(reader.stop_reason().find("offset"), std::string::npos) << reader.stop_reason();
      EXPECT_TRUE(reader.stop_reason().find("truncated") != std::string::npos ||
                  reader.stop_reason().find("cut short") != std::string::npos)
          << reader.stop_reason();
    }
  }
}

/// Replaces the first occurrence of `from` by `to` (same length) in `bytes`, after `start`.
std::size_t patch(std::vector<std::byte>& bytes, std::string_view from, std::string_view to,
                  std::size_t start = 0) {
  const auto* b = reinterpret_cast<const char*>(bytes.data());
  const std::string_view all(b, bytes.size());
  const std::size_t at = all.find(from, start);
  if (at == std::string_view::npos) return at;
  std::memcpy(bytes.data() + at, to.data(), to.size());
  return at;
}

TEST(BagReader, AChunkWithAnUnknownCompressionIsSkippedWithItsOffsetTheRestIsRead) {
  std::vector<Written> written;
  const Ros1BagWriter w =
      make_bag(Ros1BagWriter::Options::with(Ros1BagWriter::Compression::kLz4, 4096), 100, written);
  std::vector<std::byte> bytes = w.bytes();
  const std::uint64_t second = w.chunk_offsets().at(1);
  ASSERT_NE(patch(bytes, "compression=lz4", "compression=zip", second), std::string_view::npos);
  for (const bool use_index : {true, false}) {
    ros1::BagReader reader;
    std::string error;
    ASSERT_TRUE(reader.open_bytes(bytes, error, reader_options(use_index))) << error;
    const std::size_t got = read_all(reader).size();
    EXPECT_LT(got, written.size());
    EXPECT_GT(got, written.size() / 2) << "only one of many chunks is lost";
    EXPECT_EQ(reader.counters().chunks_bad, 1u);
    ASSERT_FALSE(reader.issues().empty());
    const ros1::BagIssue& issue = reader.issues().back();
    EXPECT_EQ(issue.offset, second);
    EXPECT_NE(issue.what.find("unknown compression 'zip'"), std::string::npos) << issue.what;
    EXPECT_NE(issue.what.find("offset " + std::to_string(second)), std::string::npos) << issue.what;
  }
}

TEST(BagReader, CorruptCompressedDataCostsOnlyItsChunk) {
  for (const auto compression :
       {Ros1BagWriter::Compression::kBz2, Ros1BagWriter::Compression::kLz4}) {
    std::vector<Written> written;
    const Ros1BagWriter w = make_bag(Ros1BagWriter::Options::with(compression, 4096), 100, written);
    std::vector<std::byte> bytes = w.bytes();
    const std::uint64_t victim = w.chunk_offsets().at(2);
    // Past the record's header: scramble the middle of its compressed data.
    for (std::size_t k = 80; k < 120; ++k) bytes[victim + k] ^= std::byte{0x5a};
    ros1::BagReader reader;
    std::string error;
    ASSERT_TRUE(reader.open_bytes(bytes, error)) << error;
    const std::size_t got = read_all(reader).size();
    EXPECT_LT(got, written.size());
    EXPECT_GT(got, written.size() / 2);
    EXPECT_EQ(reader.counters().chunks_bad, 1u);
    bool named = false;
    for (const auto& i : reader.issues()) named = named || i.offset == victim;
    EXPECT_TRUE(named) << "no issue names the corrupt chunk at " << victim;
  }
}

TEST(BagReader, UnknownOpsAreSkippedAndReported) {
  std::vector<Written> written;
  Ros1BagWriter w = make_bag(
      Ros1BagWriter::Options::with(Ros1BagWriter::Compression::kNone, 4096, false), 50, written);
  // A record with op 0x42 appended after the data (a newer writer's extension, say).
  std::vector<std::byte> bytes = w.bytes();
  const std::uint64_t at = bytes.size();
  const std::string header =
      std::string("\x04\0\0\0op=\x42", 8) + std::string("\x06\0\0\0x=abcd", 10);
  const std::uint32_t header_len = static_cast<std::uint32_t>(header.size());
  const std::uint32_t data_len = 5;
  bytes.resize(bytes.size() + 8 + header.size() + data_len);
  std::memcpy(bytes.data() + at, &header_len, 4);
  std::memcpy(bytes.data() + at + 4, header.data(), header.size());
  std::memcpy(bytes.data() + at + 4 + header.size(), &data_len, 4);
  ros1::BagReader reader;
  std::string error;
  ASSERT_TRUE(reader.open_bytes(bytes, error)) << error;
  EXPECT_EQ(read_all(reader).size(), written.size());
  EXPECT_EQ(reader.counters().unknown_records, 1u);
  ASSERT_FALSE(reader.issues().empty());
  EXPECT_EQ(reader.issues().back().offset, at);
  EXPECT_NE(reader.issues().back().what.find("unknown op 0x42"), std::string::npos)
      << reader.issues().back().what;
  EXPECT_TRUE(reader.stop_reason().empty()) << "skipped, not fatal";
}

TEST(BagReader, AMessageOnAnUndefinedConnectionIsSkippedWithItsOffset) {
  Ros1BagWriter w(
      Ros1BagWriter::Options::with(Ros1BagWriter::Compression::kNone, 768 * 1024, false));
  const std::uint32_t c = w.add_connection("/a", "std_msgs/UInt32", "md5", "uint32 data\n");
  const std::vector<std::byte> four(4, std::byte{1});
  w.write(c, 1, four);
  w.write_orphan(7, 2, four);
  w.write(c, 3, four);
  w.close();
  ros1::BagReader reader;
  std::string error;
  ASSERT_TRUE(reader.open_bytes(w.bytes(), error)) << error;
  EXPECT_EQ(read_all(reader).size(), 2u);
  EXPECT_EQ(reader.counters().orphan_messages, 1u);
  bool found = false;
  for (const auto& i : reader.issues()) {
    found = found || (i.what.find("connection 7") != std::string::npos &&
                      i.what.find("offset " + std::to_string(i.offset)) != std::string::npos);
  }
  EXPECT_TRUE(found);
}

TEST(BagReader, ProgressReachesTheFileSize) {
  std::vector<Written> written;
  const Ros1BagWriter w =
      make_bag(Ros1BagWriter::Options::with(Ros1BagWriter::Compression::kBz2, 4096), 200, written);
  for (const bool use_index : {true, false}) {
    std::vector<std::pair<std::uint64_t, std::uint64_t>> calls;
    ros1::BagReader reader;
    std::string error;
    ros1::BagReaderOptions options = reader_options(use_index);
    options.progress = [&](std::uint64_t done, std::uint64_t total) {
      calls.emplace_back(done, total);
    };
    ASSERT_TRUE(reader.open_bytes(w.bytes(), error, options)) << error;
    read_all(reader);
    ASSERT_GT(calls.size(), 5u);
    for (std::size_t i = 1; i < calls.size(); ++i) EXPECT_GT(calls[i].first, calls[i - 1].first);
    EXPECT_EQ(calls.back().first, w.bytes().size());
    EXPECT_EQ(calls.back().second, w.bytes().size());
  }
}

}  // namespace ros1_bag_reader_test
}  // namespace posed::testing
