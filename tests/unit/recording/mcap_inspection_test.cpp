// inspect_mcap (posectl inspect FILE.mcap): per-channel counts, rates, spans, typical periods and
// the largest gaps with their log time and file offset; and the errors of a damaged file with
// their offsets: a chunk that fails its CRC, a file cut short, records of unknown opcodes.

#include "drivers/recording/mcap_inspection.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "drivers/recording/mcap_format.hpp"
#include "drivers/recording/mcap_writer.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "tests/unit/recording/temp_dir.hpp"

namespace posed::drivers::recording {
namespace mcap_inspection_test {

constexpr std::uint64_t kT0 = 50'000'000'000;  // [ns]
constexpr std::uint64_t kMs = 1'000'000;

/// /imu at 100 Hz for 1 s with two holes: nothing between 300 and 360 ms, nor 700 and 740 ms.
std::vector<std::uint64_t> imu_times() {
  std::vector<std::uint64_t> t;
  for (std::uint64_t ms = 0; ms <= 1000; ms += 10) {
    if ((ms > 300 && ms < 360) || (ms > 700 && ms < 740)) continue;
    t.push_back(kT0 + ms * kMs);
  }
  return t;
}

struct Written {
  std::vector<McapChunkInfo> chunks;
};

Written write_rig(const std::string& path, McapCompression compression = McapCompression::kLz4) {
  McapWriterOptions o;
  o.compression = compression;
  o.chunk_size_bytes = 2048;
  o.fsync_on_close = false;
  McapWriter w;
  std::string error;
  EXPECT_TRUE(w.open(path, o, error)) << error;
  w.write_metadata(raw::kMetadataName, {{std::string(raw::kHostToWallKey), "1700000000000000000"}});
  const std::string text = "int32 a\n";
  const auto schema = w.add_schema("t/msg/A", "ros2msg",
                                   {reinterpret_cast<const std::byte*>(text.data()), text.size()});
  const auto imu = w.add_channel("/posed/raw/imu", raw::kMessageEncoding, 0,
                                 {{std::string(raw::kStreamKey), "imu"},
                                  {std::string(raw::kWireFormatKey), "a9-serial"},
                                  {std::string(raw::kSourceChannelKey), "0"}});
  const auto pose = w.add_channel("/posed/pose", "cdr", schema, {});
  w.add_channel("/never", "cdr", 0, {});  // defined, never written
  const std::vector<std::byte> payload(40, std::byte{0x2A});
  std::uint32_t seq = 0;
  for (const std::uint64_t t : imu_times()) {
    EXPECT_TRUE(w.write_message(imu, seq++, t, t, payload));
    if ((t - kT0) % (100 * kMs) == 0) {
      EXPECT_TRUE(w.write_message(pose, seq, t, t, payload));
    }
  }
  EXPECT_TRUE(w.close()) << w.error();
  return {w.chunks()};
}

const McapChannelStats& by_topic(const McapInspection& r, const std::string& topic) {
  for (const auto& c : r.channels) {
    if (c.channel.topic == topic) return c;
  }
  static const McapChannelStats none;
  ADD_FAILURE() << "no channel " << topic;
  return none;
}

TEST(McapInspection, CountsRatesSpansPeriodsAndTheLargestGapsWithWhereTheyAre) {
  test::TempDir dir("inspect");
  const std::string path = dir.file("rig.mcap");
  const Written w = write_rig(path);
  McapInspection r;
  std::string error;
  ASSERT_TRUE(inspect_mcap(path, {}, r, error)) << error;
  EXPECT_TRUE(r.complete);
  EXPECT_TRUE(r.issues.empty());
  EXPECT_TRUE(r.summary.usable());
  ASSERT_EQ(r.channels.size(), 3u);

  const McapChannelStats& imu = by_topic(r, "/posed/raw/imu");
  const auto times = imu_times();
  EXPECT_EQ(imu.messages, times.size());
  EXPECT_EQ(imu.bytes, 40 * times.size());
  EXPECT_EQ(imu.first_log_ns, kT0);
  EXPECT_EQ(imu.last_log_ns, kT0 + 1000 * kMs);
  EXPECT_NEAR(imu.rate_hz, static_cast<double>(times.size() - 1), 1e-9);  // over 1 s
  EXPECT_EQ(imu.median_interval_ns, static_cast<std::int64_t>(10 * kMs));
  EXPECT_EQ(imu.channel.metadata.at(std::string(raw::kWireFormatKey)), "a9-serial");
  EXPECT_EQ(imu.schema_name, "");
  // The 60 ms and 40 ms intervals are over 3 x 10 ms; nothing else is.
  EXPECT_EQ(imu.gaps, 2u);
  ASSERT_EQ(imu.largest_gaps.size(), 2u);
  EXPECT_EQ(imu.largest_gaps[0].length_ns, static_cast<std::int64_t>(60 * kMs));
  EXPECT_EQ(imu.largest_gaps[0].after_log_ns, kT0 + 300 * kMs);
  EXPECT_EQ(imu.largest_gaps[1].length_ns, static_cast<std::int64_t>(40 * kMs));
  EXPECT_EQ(imu.largest_gaps[1].after_log_ns, kT0 + 700 * kMs);
  // Where: the Chunk holding the message after the gap.
  for (const McapGap& g : imu.largest_gaps) {
    const std::uint64_t next = g.after_log_ns + static_cast<std::uint64_t>(g.length_ns);
    bool found = false;
    for (const auto& c : w.chunks) {
      if (c.start_offset == g.record_offset) {
        found = true;
        EXPECT_LE(c.message_start_time_ns, next);
        EXPECT_GE(c.message_end_time_ns, next);
      }
    }
    EXPECT_TRUE(found) << "offset " << g.record_offset << " is not a Chunk";
  }

  const McapChannelStats& pose = by_topic(r, "/posed/pose");
  EXPECT_EQ(pose.schema_name, "t/msg/A");
  EXPECT_EQ(pose.messages, 11u);  // every 100 ms from 0 to 1000 ms
  EXPECT_EQ(pose.median_interval_ns, static_cast<std::int64_t>(100 * kMs));
  EXPECT_EQ(pose.gaps, 0u);
  EXPECT_TRUE(pose.largest_gaps.empty());

  const McapChannelStats& never = by_topic(r, "/never");
  EXPECT_EQ(never.messages, 0u);
  EXPECT_EQ(never.rate_hz, 0.0);

  EXPECT_EQ(r.messages, times.size() + 11);
  EXPECT_EQ(r.first_log_ns, kT0);
  EXPECT_EQ(r.last_log_ns, kT0 + 1000 * kMs);
  ASSERT_TRUE(r.host_to_wall.has_value());
  EXPECT_EQ(r.host_to_wall->wall_minus_host.ns, 1'700'000'000'000'000'000);
}

TEST(McapInspection, GapFactorAndGapCountAreOptions) {
  test::TempDir dir("inspect_opts");
  const std::string path = dir.file("rig.mcap");
  write_rig(path);
  McapInspectOptions o;
  o.gap_factor = 5.0;  // only the 60 ms interval exceeds 50 ms
  o.max_gaps = 1;
  McapInspection r;
  std::string error;
  ASSERT_TRUE(inspect_mcap(path, o, r, error)) << error;
  const McapChannelStats& imu = by_topic(r, "/posed/raw/imu");
  EXPECT_EQ(imu.gaps, 1u);
  ASSERT_EQ(imu.largest_gaps.size(), 1u);
  EXPECT_EQ(imu.largest_gaps[0].length_ns, static_cast<std::int64_t>(60 * kMs));
}

TEST(McapInspection, AChunkFailingItsCrcIsAnErrorAtItsOffset) {
  test::TempDir dir("inspect_crc");
  const std::string path = dir.file("rig.mcap");
  const Written w = write_rig(path, McapCompression::kNone);
  ASSERT_GE(w.chunks.size(), 3u);
  const McapChunkInfo& victim = w.chunks[1];
  auto bytes = test::slurp(path);
  // A byte in the middle of the chunk's records: its CRC no longer matches.
  bytes[victim.start_offset + victim.chunk_length / 2] ^= std::byte{0x5A};
  McapInspection r;
  std::string error;
  ASSERT_TRUE(inspect_mcap_bytes(bytes, {}, r, error)) << error;
  EXPECT_FALSE(r.complete);
  EXPECT_EQ(r.counters.chunks_bad, 1u);
  bool reported = false;
  for (const auto& i : r.issues) {
    if (i.offset == victim.start_offset && i.what.find("CRC") != std::string::npos) reported = true;
  }
  EXPECT_TRUE(reported) << (r.issues.empty() ? "no issue" : r.issues.front().what);
  // The messages of the lost chunk show up as a gap on the channel.
  EXPECT_LT(by_topic(r, "/posed/raw/imu").messages, imu_times().size());
  EXPECT_GE(by_topic(r, "/posed/raw/imu").gaps, 1u);
}

TEST(McapInspection, AFileCutShortSaysWhereItStops) {
  test::TempDir dir("inspect_cut");
  const std::string path = dir.file("rig.mcap");
  const Written w = write_rig(path);
  ASSERT_GE(w.chunks.size(), 3u);
  const McapChunkInfo& cut_in = w.chunks[2];
  const auto bytes = test::slurp(path);
  const std::vector<std::byte> cut(
      bytes.begin(),
      bytes.begin() + static_cast<std::ptrdiff_t>(cut_in.start_offset + cut_in.chunk_length / 2));
  McapInspection r;
  std::string error;
  ASSERT_TRUE(inspect_mcap_bytes(cut, {}, r, error)) << error;
  EXPECT_FALSE(r.complete);
  EXPECT_FALSE(r.summary.footer_found);
  EXPECT_NE(r.stop_reason.find("truncated Chunk record"), std::string::npos) << r.stop_reason;
  EXPECT_NE(r.stop_reason.find("offset " + std::to_string(cut_in.start_offset)), std::string::npos)
      << r.stop_reason;
  bool at_offset = false;
  for (const auto& i : r.issues) at_offset = at_offset || i.offset == cut_in.start_offset;
  EXPECT_TRUE(at_offset);
  // Everything before the cut was read.
  std::uint64_t before = 0;
  for (std::size_t c = 0; c < 2; ++c) before += w.chunks[c].message_count;
  EXPECT_EQ(r.messages, before);
}

TEST(McapInspection, UnknownRecordsAreListedWithTheirOffsets) {
  // magic, Header, Channel, an extension record, a Chunk holding an unknown record and a
  // Message, DataEnd, Footer, magic.
  std::vector<std::byte> f;
  mcap::Out o(f);
  o.put(mcap::kMagic.data(), 8);
  auto at = o.begin_record(mcap::Op::kHeader);
  o.str("");
  o.str("hand");
  o.finish_record(at);
  at = o.begin_record(mcap::Op::kChannel);
  o.u16(1);
  o.u16(0);
  o.str("/x");
  o.str("posed-raw");
  o.u32(0);
  o.finish_record(at);
  const std::uint64_t extension_at = f.size();
  at = o.begin_record(static_cast<mcap::Op>(0x80));
  o.u64(7);
  o.finish_record(at);
  std::vector<std::byte> records;
  mcap::Out r(records);
  const std::uint64_t inner_at = records.size();
  auto rat = r.begin_record(static_cast<mcap::Op>(0x42));
  r.u32(1);
  r.finish_record(rat);
  rat = r.begin_record(mcap::Op::kMessage);
  r.u16(1);
  r.u32(0);
  r.u64(kT0);
  r.u64(kT0);
  r.put("hi", 2);
  r.finish_record(rat);
  const std::uint64_t chunk_at = f.size();
  at = o.begin_record(mcap::Op::kChunk);
  o.u64(kT0);
  o.u64(kT0);
  o.u64(records.size());
  o.u32(0);  // no CRC
  o.str("");
  o.u64(records.size());
  o.bytes(records);
  o.finish_record(at);
  at = o.begin_record(mcap::Op::kDataEnd);
  o.u32(0);
  o.finish_record(at);
  at = o.begin_record(mcap::Op::kFooter);
  o.u64(0);
  o.u64(0);
  o.u32(0);
  o.finish_record(at);
  o.put(mcap::kMagic.data(), 8);

  McapInspection insp;
  std::string error;
  ASSERT_TRUE(inspect_mcap_bytes(f, {}, insp, error)) << error;
  EXPECT_TRUE(insp.complete);  // skipping unknown records is what the spec asks for
  EXPECT_EQ(insp.messages, 1u);
  EXPECT_EQ(insp.counters.unknown_records, 2u);
  ASSERT_EQ(insp.unknown_records.size(), 2u);
  EXPECT_EQ(insp.unknown_records[0].offset, extension_at);
  EXPECT_EQ(insp.unknown_records[0].opcode, 0x80);
  EXPECT_EQ(insp.unknown_records[0].length, 8u);
  EXPECT_EQ(insp.unknown_records[0].chunk_byte, -1);
  EXPECT_EQ(insp.unknown_records[1].offset, chunk_at);
  EXPECT_EQ(insp.unknown_records[1].opcode, 0x42);
  EXPECT_EQ(insp.unknown_records[1].chunk_byte, static_cast<std::int64_t>(inner_at));
}

TEST(McapInspection, NotMcapIsAnErrorNamingTheProblem) {
  const std::string text = "PK\x03\x04 a zip file";
  McapInspection r;
  std::string error;
  EXPECT_FALSE(inspect_mcap_bytes({reinterpret_cast<const std::byte*>(text.data()), text.size()},
                                  {}, r, error));
  EXPECT_NE(error.find("not an MCAP file"), std::string::npos) << error;
}

}  // namespace mcap_inspection_test
}  // namespace posed::drivers::recording
