// Byte-exact checks of the MCAP writer against the specification (mcap.dev/spec), with a parser
// written here independently of the reader under test: magic, record framing, Header, Chunk
// fields and CRC, MessageIndex offsets, DataEnd CRC, summary groups, SummaryOffsets, Footer CRC.
// No MCAP reader is packaged in Debian, so this is the conformance check.

#include <gtest/gtest.h>
#include <lz4frame.h>

#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "drivers/recording/crc32.hpp"
#include "drivers/recording/mcap_writer.hpp"
#include "tests/unit/recording/temp_dir.hpp"

namespace posed::drivers::recording {
namespace {

const std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

struct Rd {
  std::span<const std::byte> b;
  std::size_t p = 0;
  template <class T>
  T get() {
    T v{};
    EXPECT_LE(p + sizeof(T), b.size());
    if (p + sizeof(T) > b.size()) return v;
    std::memcpy(&v, b.data() + p, sizeof(T));
    p += sizeof(T);
    return v;
  }
  std::string str() {
    const auto n = get<std::uint32_t>();
    std::string s(reinterpret_cast<const char*>(b.data() + p), n);
    p += n;
    return s;
  }
};

struct Rec {
  std::uint8_t op;
  std::size_t offset;  // of the opcode
  std::span<const std::byte> body;
};

std::vector<Rec> records(std::span<const std::byte> file, std::size_t from, std::size_t to) {
  std::vector<Rec> out;
  std::size_t p = from;
  while (p < to) {
    Rd r{file, p};
    const auto op = r.get<std::uint8_t>();
    const auto len = r.get<std::uint64_t>();
    out.push_back({op, p, file.subspan(p + 9, len)});
    p += 9 + len;
  }
  EXPECT_EQ(p, to);
  return out;
}

std::span<const std::byte> as_bytes(const std::string& s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

/// Bit by bit, straight from the definition: the reference the fast paths must equal.
std::uint32_t crc32_bitwise(const std::vector<std::byte>& data, std::size_t from, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = from; i < from + n; ++i) {
    c ^= static_cast<std::uint8_t>(data[i]);
    for (int k = 0; k < 8; ++k) c = (c & 1u) != 0 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xFFFFFFFFu;
}

TEST(Crc32, EveryLengthAlignmentAndSplitMatchesTheDefinition) {
  // Lengths around the folding path's 64-byte minimum and 16-byte steps, at odd addresses, fed
  // whole and in two pieces: the carry-less multiplication path, the tables and their joins.
  std::vector<std::byte> data(5000);
  std::uint32_t x = 12345;
  for (auto& b : data) {
    x = x * 1103515245u + 12345u;
    b = static_cast<std::byte>(x >> 24);
  }
  for (std::size_t n : {0, 1, 15, 16, 63, 64, 65, 79, 80, 127, 128, 129, 1000, 1023, 4093}) {
    for (std::size_t from : {0, 1, 5, 8, 13}) {
      const std::uint32_t want = crc32_bitwise(data, from, n);
      EXPECT_EQ(crc32(std::span(data).subspan(from, n)), want) << n << " at " << from;
      for (std::size_t cut : {std::size_t{0}, n / 3, n / 2 + 7 <= n ? n / 2 + 7 : n, n}) {
        Crc32 split;
        split.update(std::span(data).subspan(from, cut));
        split.update(std::span(data).subspan(from + cut, n - cut));
        EXPECT_EQ(split.value(), want) << n << " at " << from << " cut " << cut;
      }
    }
  }
}

TEST(Crc32, KnownVector) {
  // The CRC-32/ISO-HDLC check value (zlib's crc32 of "123456789").
  EXPECT_EQ(crc32(as_bytes("123456789")), 0xCBF43926u);
  Crc32 split;
  split.update(as_bytes("1234"));
  split.update(as_bytes("56789"));
  EXPECT_EQ(split.value(), 0xCBF43926u);
  EXPECT_EQ(crc32({}), 0u);
}

class Layout : public ::testing::TestWithParam<McapCompression> {};

TEST_P(Layout, RecordsAreExactlyAsTheSpecSays) {
  test::TempDir dir("mcap_layout");
  const std::string path = dir.file("layout.mcap");
  McapWriterOptions opt;
  opt.compression = GetParam();
  opt.profile = "";
  opt.library = "posed-test";
  opt.chunk_size_bytes = 200;  // a few chunks
  McapWriter w;
  std::string error;
  ASSERT_TRUE(w.open(path, opt, error)) << error;
  const std::string schema_text = "float64 x\n";
  const auto sid = w.add_schema("pkg/msg/X", "ros2msg", as_bytes(schema_text));
  EXPECT_EQ(sid, 1);
  const auto c0 = w.add_channel("/a", "cdr", sid, {{"k", "v"}});
  const auto c1 = w.add_channel("/posed/raw/imu", "posed-raw", 0, {});
  EXPECT_EQ(c0, 0);
  EXPECT_EQ(c1, 1);
  // Repetitive payloads so that lz4/zstd actually compress the chunks.
  std::vector<std::byte> payload(40, std::byte{0x5A});
  for (std::uint32_t i = 0; i < 20; ++i) {
    payload[0] = static_cast<std::byte>(i);
    ASSERT_TRUE(w.write_message(i % 2 == 0 ? c0 : c1, i, 1000 + i, 2000 + i, payload));
  }
  ASSERT_TRUE(w.write_metadata("posed", {{"host_to_wall_ns", "42"}}));
  ASSERT_TRUE(w.close()) << w.error();
  const auto file = test::slurp(path);
  ASSERT_GT(file.size(), 16u);

  // Magic at both ends.
  EXPECT_EQ(std::memcmp(file.data(), kMagic, 8), 0);
  EXPECT_EQ(std::memcmp(file.data() + file.size() - 8, kMagic, 8), 0);

  // Footer: the last 29 bytes before the trailing magic.
  const std::size_t footer_at = file.size() - 8 - 29;
  Rd f{file, footer_at};
  EXPECT_EQ(f.get<std::uint8_t>(), 0x02);
  EXPECT_EQ(f.get<std::uint64_t>(), 20u);
  const auto summary_start = f.get<std::uint64_t>();
  const auto summary_offset_start = f.get<std::uint64_t>();
  const auto summary_crc = f.get<std::uint32_t>();
  ASSERT_GT(summary_start, 8u);
  ASSERT_GT(summary_offset_start, summary_start);
  ASSERT_LT(summary_offset_start, footer_at);
  EXPECT_EQ(summary_crc,
            crc32(std::span(file).subspan(summary_start, footer_at + 1 + 8 + 16 - summary_start)));

  // Data section: Header, then chunks each followed by their MessageIndex records, Metadata,
  // DataEnd (the last record before the summary).
  const auto data = records(file, 8, summary_start);
  ASSERT_GE(data.size(), 4u);
  EXPECT_EQ(data.front().op, 0x01);
  {
    Rd h{data.front().body};
    EXPECT_EQ(h.str(), "");
    EXPECT_EQ(h.str(), "posed-test");
  }
  const Rec& data_end = data.back();
  EXPECT_EQ(data_end.op, 0x0F);
  ASSERT_EQ(data_end.body.size(), 4u);
  {
    Rd d{data_end.body};
    EXPECT_EQ(d.get<std::uint32_t>(), crc32(std::span(file).subspan(0, data_end.offset)));
  }

  struct ChunkSeen {
    std::size_t offset, length;
    std::uint64_t start, end;
    std::string compression;
    std::uint64_t compressed, uncompressed;
    std::map<std::uint16_t, std::size_t> index_offsets;
    std::size_t index_length = 0;
  };
  std::vector<ChunkSeen> chunks;
  std::uint32_t messages_seen = 0;
  bool channel_defined[2] = {false, false};
  for (std::size_t i = 1; i + 1 < data.size(); ++i) {
    const Rec& r = data[i];
    if (r.op == 0x06) {
      Rd c{r.body};
      ChunkSeen cs{};
      cs.offset = r.offset;
      cs.length = 9 + r.body.size();
      cs.start = c.get<std::uint64_t>();
      cs.end = c.get<std::uint64_t>();
      cs.uncompressed = c.get<std::uint64_t>();
      const auto crc = c.get<std::uint32_t>();
      cs.compression = c.str();
      cs.compressed = c.get<std::uint64_t>();
      ASSERT_EQ(c.p + cs.compressed, r.body.size());
      std::vector<std::byte> plain(cs.uncompressed);
      auto stored = r.body.subspan(c.p, cs.compressed);
      if (cs.compression.empty()) {
        ASSERT_EQ(cs.compressed, cs.uncompressed);
        std::memcpy(plain.data(), stored.data(), stored.size());
      } else {
        ASSERT_EQ(cs.compression, "lz4") << "zstd chunks are checked by the reader round trip";
        LZ4F_dctx* ctx = nullptr;
        LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION);
        std::size_t dst = plain.size(), src = stored.size();
        EXPECT_EQ(LZ4F_decompress(ctx, plain.data(), &dst, stored.data(), &src, nullptr), 0u);
        EXPECT_EQ(dst, plain.size());
        LZ4F_freeDecompressionContext(ctx);
      }
      EXPECT_EQ(crc, crc32(plain));
      // Inside: Schema/Channel before the first message on them, then Messages.
      std::uint64_t lo = ~0ull, hi = 0;
      for (const Rec& in : records(plain, 0, plain.size())) {
        if (in.op == 0x04) {
          Rd ch{in.body};
          const auto id = ch.get<std::uint16_t>();
          ASSERT_LT(id, 2);
          channel_defined[id] = true;
        } else if (in.op == 0x05) {
          Rd m{in.body};
          const auto ch = m.get<std::uint16_t>();
          const auto seq = m.get<std::uint32_t>();
          const auto log = m.get<std::uint64_t>();
          const auto pub = m.get<std::uint64_t>();
          EXPECT_TRUE(channel_defined[ch]);
          EXPECT_EQ(seq, messages_seen);
          EXPECT_EQ(log, 1000 + seq);
          EXPECT_EQ(pub, 2000 + seq);
          EXPECT_EQ(in.body.size() - m.p, 40u);
          lo = std::min(lo, log);
          hi = std::max(hi, log);
          ++messages_seen;
        } else {
          EXPECT_EQ(in.op, 0x03) << "only Schema/Channel/Message inside chunks";
        }
      }
      EXPECT_EQ(cs.start, lo);
      EXPECT_EQ(cs.end, hi);
      // MessageIndex records follow; their offsets point at Message records in `plain`.
      std::size_t j = i + 1;
      for (; j < data.size() && data[j].op == 0x07; ++j) {
        Rd mi{data[j].body};
        const auto ch = mi.get<std::uint16_t>();
        cs.index_offsets[ch] = data[j].offset;
        cs.index_length += 9 + data[j].body.size();
        const auto n = mi.get<std::uint32_t>();
        ASSERT_EQ(n % 16, 0u);
        for (std::uint32_t k = 0; k < n / 16; ++k) {
          const auto t = mi.get<std::uint64_t>();
          const auto off = mi.get<std::uint64_t>();
          ASSERT_LT(off + 9 + 22, plain.size() + 1);
          Rd m{plain, static_cast<std::size_t>(off)};
          EXPECT_EQ(m.get<std::uint8_t>(), 0x05);
          m.get<std::uint64_t>();
          EXPECT_EQ(m.get<std::uint16_t>(), ch);
          m.get<std::uint32_t>();
          EXPECT_EQ(m.get<std::uint64_t>(), t);
        }
      }
      chunks.push_back(cs);
      i = j - 1;
    } else {
      EXPECT_EQ(r.op, 0x0C) << "unexpected record in the data section at " << r.offset;
    }
  }
  EXPECT_EQ(messages_seen, 20u);
  EXPECT_GE(chunks.size(), 3u);
  if (GetParam() == McapCompression::kLz4) {
    bool any_compressed = false;
    for (const auto& c : chunks) any_compressed = any_compressed || c.compression == "lz4";
    EXPECT_TRUE(any_compressed);
  }

  // Summary: grouped by opcode; SummaryOffsets describe each group exactly.
  const auto summary = records(file, summary_start, summary_offset_start);
  std::map<std::uint8_t, std::pair<std::size_t, std::size_t>> groups;  // op -> (start, length)
  std::uint8_t last_op = 0;
  std::size_t chunk_index_seen = 0;
  for (const Rec& r : summary) {
    if (r.op != last_op) {
      EXPECT_EQ(groups.count(r.op), 0u) << "summary records must be grouped by opcode";
      groups[r.op] = {r.offset, 0};
      last_op = r.op;
    }
    groups[r.op].second += 9 + r.body.size();
    if (r.op == 0x0B) {
      Rd s{r.body};
      EXPECT_EQ(s.get<std::uint64_t>(), 20u);  // message_count
      EXPECT_EQ(s.get<std::uint16_t>(), 1u);   // schema_count
      EXPECT_EQ(s.get<std::uint32_t>(), 2u);   // channel_count
      EXPECT_EQ(s.get<std::uint32_t>(), 0u);   // attachment_count
      EXPECT_EQ(s.get<std::uint32_t>(), 1u);   // metadata_count
      EXPECT_EQ(s.get<std::uint32_t>(), chunks.size());
      EXPECT_EQ(s.get<std::uint64_t>(), 1000u);
      EXPECT_EQ(s.get<std::uint64_t>(), 1019u);
      EXPECT_EQ(s.get<std::uint32_t>(), 2u * (2 + 8));
      EXPECT_EQ(s.get<std::uint16_t>(), 0u);
      EXPECT_EQ(s.get<std::uint64_t>(), 10u);
      EXPECT_EQ(s.get<std::uint16_t>(), 1u);
      EXPECT_EQ(s.get<std::uint64_t>(), 10u);
      EXPECT_TRUE(groups.count(0x04)) << "Channels must precede Statistics";
    } else if (r.op == 0x08) {
      ASSERT_LT(chunk_index_seen, chunks.size());
      const auto& c = chunks[chunk_index_seen++];
      Rd x{r.body};
      EXPECT_EQ(x.get<std::uint64_t>(), c.start);
      EXPECT_EQ(x.get<std::uint64_t>(), c.end);
      EXPECT_EQ(x.get<std::uint64_t>(), c.offset);
      EXPECT_EQ(x.get<std::uint64_t>(), c.length);
      const auto map_len = x.get<std::uint32_t>();
      EXPECT_EQ(map_len, c.index_offsets.size() * 10);
      for (std::size_t k = 0; k < c.index_offsets.size(); ++k) {
        const auto ch = x.get<std::uint16_t>();
        EXPECT_EQ(x.get<std::uint64_t>(), c.index_offsets.at(ch));
      }
      EXPECT_EQ(x.get<std::uint64_t>(), c.index_length);
      EXPECT_EQ(x.str(), c.compression);
      EXPECT_EQ(x.get<std::uint64_t>(), c.compressed);
      EXPECT_EQ(x.get<std::uint64_t>(), c.uncompressed);
    } else if (r.op == 0x04) {
      Rd ch{r.body};
      const auto id = ch.get<std::uint16_t>();
      const auto schema = ch.get<std::uint16_t>();
      const auto topic = ch.str();
      const auto enc = ch.str();
      if (id == 0) {
        EXPECT_EQ(schema, 1);
        EXPECT_EQ(topic, "/a");
        EXPECT_EQ(enc, "cdr");
        EXPECT_EQ(ch.get<std::uint32_t>(), 4u + 1 + 4 + 1);
        EXPECT_EQ(ch.str(), "k");
        EXPECT_EQ(ch.str(), "v");
      } else {
        EXPECT_EQ(schema, 0);
        EXPECT_EQ(topic, "/posed/raw/imu");
        EXPECT_EQ(enc, "posed-raw");
        EXPECT_EQ(ch.get<std::uint32_t>(), 0u);
      }
    } else if (r.op == 0x03) {
      Rd s{r.body};
      EXPECT_EQ(s.get<std::uint16_t>(), 1);
      EXPECT_EQ(s.str(), "pkg/msg/X");
      EXPECT_EQ(s.str(), "ros2msg");
      EXPECT_EQ(s.str(), schema_text);  // uint32-length-prefixed bytes
    } else {
      EXPECT_EQ(r.op, 0x0D);
    }
  }
  EXPECT_EQ(chunk_index_seen, chunks.size());
  for (int op : {0x03, 0x04, 0x0B, 0x08, 0x0D}) {
    EXPECT_TRUE(groups.count(static_cast<std::uint8_t>(op))) << op;
  }
  const auto offsets = records(file, summary_offset_start, footer_at);
  EXPECT_EQ(offsets.size(), groups.size());
  for (const Rec& r : offsets) {
    EXPECT_EQ(r.op, 0x0E);
    Rd s{r.body};
    const auto op = s.get<std::uint8_t>();
    ASSERT_TRUE(groups.count(op));
    EXPECT_EQ(s.get<std::uint64_t>(), groups[op].first);
    EXPECT_EQ(s.get<std::uint64_t>(), groups[op].second);
  }
}

INSTANTIATE_TEST_SUITE_P(Compression, Layout,
                         ::testing::Values(McapCompression::kNone, McapCompression::kLz4));

TEST(Layout, EmptyFileIsHeaderDataEndSummaryFooter) {
  test::TempDir dir("mcap_empty");
  McapWriter w;
  std::string error;
  ASSERT_TRUE(w.open(dir.file("e.mcap"), {}, error)) << error;
  ASSERT_TRUE(w.close());
  const auto file = test::slurp(dir.file("e.mcap"));
  const std::size_t footer_at = file.size() - 8 - 29;
  Rd f{file, footer_at + 9};
  const auto summary_start = f.get<std::uint64_t>();
  const auto recs = records(file, 8, summary_start);
  ASSERT_EQ(recs.size(), 2u);
  EXPECT_EQ(recs[0].op, 0x01);
  EXPECT_EQ(recs[1].op, 0x0F);
}

}  // namespace
}  // namespace posed::drivers::recording
