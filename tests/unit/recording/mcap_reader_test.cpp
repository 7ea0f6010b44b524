// McapReader: round trips through the writer (none/lz4/zstd), files cut at many offsets (every
// complete chunk is recovered and the reader says where it stopped), and bad input: wrong magic,
// bad CRCs, unknown opcodes and compressions, channels without their schema.

#include "drivers/recording/mcap_reader.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/recording/crc32.hpp"
#include "drivers/recording/mcap_format.hpp"
#include "drivers/recording/mcap_writer.hpp"
#include "tests/unit/recording/temp_dir.hpp"

namespace posed::drivers::recording {
namespace {

std::vector<std::byte> payload_for(std::uint32_t i) {
  // Varying lengths and contents, partly compressible.
  std::vector<std::byte> p(20 + (i * 37) % 300);
  for (std::size_t k = 0; k < p.size(); ++k) {
    p[k] = static_cast<std::byte>(k % 7 == 0 ? (i * 13 + k) & 0xFF : 0x41);
  }
  return p;
}

struct Written {
  std::vector<McapChunkInfo> chunks;
  std::uint32_t messages = 0;
};

/// A test file's writer options: `compression`, chunks of `chunk_bytes`, no fsync.
McapWriterOptions writer_options(McapCompression compression, std::size_t chunk_bytes) {
  McapWriterOptions opt;
  opt.compression = compression;
  opt.chunk_size_bytes = chunk_bytes;
  opt.fsync_on_close = false;
  return opt;
}

Written write_file(const std::string& path, McapCompression compression, std::uint32_t n,
                   std::size_t chunk_size = 2048) {
  McapWriter w;
  std::string error;
  EXPECT_TRUE(w.open(path, writer_options(compression, chunk_size), error)) << error;
  const std::string text = "int32 a\n";
  const auto sid = w.add_schema("t/msg/A", "ros2msg",
                                {reinterpret_cast<const std::byte*>(text.data()), text.size()});
  const auto a = w.add_channel("/a", "cdr", sid, {{"posed.stream", "a"}});
  const auto b = w.add_channel("/b", "posed-raw", 0, {});
  for (std::uint32_t i = 0; i < n; ++i) {
    EXPECT_TRUE(w.write_message(i % 3 == 0 ? b : a, i, 1'000'000 + i * 1000ull, i, payload_for(i)));
  }
  EXPECT_TRUE(w.close()) << w.error();
  return {w.chunks(), n};
}

std::vector<std::uint32_t> read_sequences(McapReader& r) {
  std::vector<std::uint32_t> seq;
  McapMessage m;
  while (r.next(m)) {
    EXPECT_EQ(m.log_time_ns, 1'000'000 + m.sequence * 1000ull);
    const auto want = payload_for(m.sequence);
    EXPECT_TRUE(m.data.size() == want.size() &&
                std::memcmp(m.data.data(), want.data(), want.size()) == 0)
        << "payload of message " << m.sequence;
    EXPECT_EQ(m.channel->topic, m.sequence % 3 == 0 ? "/b" : "/a");
    seq.push_back(m.sequence);
  }
  return seq;
}

/// Resident memory of this process's mapping of `path` [kB] (from /proc/self/smaps), 0 if none.
std::size_t mapped_resident_kb(const std::string& path) {
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool in_file = false;
  std::size_t kb = 0;
  while (std::getline(smaps, line)) {
    if (line.empty()) continue;
    if (std::isxdigit(static_cast<unsigned char>(line[0])) != 0 && line.find('-') < 17) {
      in_file = line.size() >= path.size() &&
                line.compare(line.size() - path.size(), path.size(), path) == 0;
    } else if (in_file && line.rfind("Rss:", 0) == 0) {
      std::istringstream in(line.substr(4));
      std::size_t v = 0;
      in >> v;
      kb += v;
    }
  }
  return kb;
}

/// 1024 messages of `message_bytes` on one raw channel, in chunks of `chunk_bytes`; `fill` writes
/// message i's bytes.
void write_large_file(const std::string& path, McapCompression compression, std::size_t chunk_bytes,
                      std::size_t message_bytes,
                      const std::function<void(std::uint32_t, std::vector<std::byte>&)>& fill) {
  McapWriter w;
  std::string error;
  ASSERT_TRUE(w.open(path, writer_options(compression, chunk_bytes), error)) << error;
  const auto ch = w.add_channel("/raw", "posed-raw", 0, {});
  std::vector<std::byte> bytes(message_bytes);
  for (std::uint32_t i = 0; i < 1024; ++i) {
    fill(i, bytes);
    ASSERT_TRUE(w.write_message(ch, i, 1'000'000 + i * 1000ull, i, bytes));
  }
  ASSERT_TRUE(w.close()) << w.error();
}

class Residency : public ::testing::TestWithParam<bool> {};

TEST_P(Residency, AReaderHoldsLittleMoreOfTheFileThanTheChunkItWalks) {
  // A replay runs a reader per stream over one mapping of the file: what each keeps resident
  // behind it adds up in posed's memory, and the data CRC reads every byte.
  test::TempDir dir("mcap_resident");
  const std::string path = dir.file("big.mcap");
  ASSERT_NO_FATAL_FAILURE(write_large_file(path, McapCompression::kNone, 64u << 10, 16u << 10,
                                           [](std::uint32_t i, std::vector<std::byte>& image) {
                                             std::memset(image.data(), static_cast<int>(i),
                                                         image.size());
                                           }));  // 16 MB in 256 chunks
  // With the CRCs checked the reader touches every byte; without, as a replay's reader that finds
  // its chunks decompressed by another, little more than the record headers, and each page
  // fault maps pages around the one touched, some behind what the reader released.
  McapReaderOptions options;
  options.verify_crcs = GetParam();
  McapReader r;
  std::string error;
  ASSERT_TRUE(r.open(path, error, options)) << error;
  McapMessage m;
  std::size_t most_kb = 0, messages = 0;
  while (r.next(m)) {
    ASSERT_EQ(m.data.size(), 16u << 10);
    EXPECT_EQ(m.data[100], static_cast<std::byte>(m.sequence & 0xFF));
    if (++messages % 16 == 0) most_kb = std::max(most_kb, mapped_resident_kb(path));
  }
  EXPECT_EQ(messages, 1024u);
  EXPECT_TRUE(r.complete());
  EXPECT_GT(most_kb, 0u) << "the mapping was found in /proc/self/smaps";
  // The chunk being walked and the step behind it. At 4 MB release steps and the CRC in 8 MB
  // ones a reader held 4.2 MB of this file.
  EXPECT_LE(most_kb, 512u) << "largest resident part of the 16 MB file's mapping";
  EXPECT_LE(mapped_resident_kb(path), 512u) << "at the end";
}

/// Writes `path` out and drops it from the page cache, so that reading it fills the cache as a
/// recording made earlier does (read-ahead's large folios, not the writes').
void drop_from_page_cache(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0) << path;
  EXPECT_EQ(::fdatasync(fd), 0);
  EXPECT_EQ(::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED), 0);
  ::close(fd);
}

TEST(Residency, ReadersSharingChunksHoldLittleOfTheFileBetweenThem) {
  // A replay's readers side by side: the first decompresses each chunk and checks the CRCs, the
  // other finds the chunks decompressed and touches little more than their headers, and a page
  // fault maps the pages around the one touched, some of them behind what it had released.
  test::TempDir dir("mcap_resident_shared");
  const std::string path = dir.file("big.mcap");
  std::uint32_t x = 12345;
  ASSERT_NO_FATAL_FAILURE(write_large_file(path, McapCompression::kLz4, 256u << 10, 64u << 10,
                                           [&x](std::uint32_t, std::vector<std::byte>& noise) {
                                             for (auto& b : noise)
                                               b = static_cast<std::byte>(
                                                   (x = x * 1664525u + 1013904223u) >> 24);
                                           }));  // 64 MB that lz4 cannot shrink
  drop_from_page_cache(path);
  McapReaderOptions options;
  options.chunk_cache = std::make_shared<McapChunkCache>();
  McapReader first, second;
  std::string error;
  ASSERT_TRUE(first.open(path, error, options)) << error;
  ASSERT_TRUE(second.open(path, error, options)) << error;
  McapMessage m;
  std::size_t most_kb = 0, messages = 0;
  for (bool more = true; more;) {
    more = first.next(m);
    if (second.next(m)) ++messages;
    if (messages % 16 == 0) most_kb = std::max(most_kb, mapped_resident_kb(path));
  }
  EXPECT_EQ(messages, 1024u);
  EXPECT_EQ(options.chunk_cache->counters().hits, options.chunk_cache->counters().misses);
  // The kernel maps a whole large folio of the page cache on a fault (up to 2 MB ahead of the
  // record touched), so each reader may hold a few MB however large the file; at 4 MB release
  // steps the two held 12.3 MB. (The pages fault-around maps behind a release, which kept 3.4 %
  // of a real recording, do not come back on a file this fresh: that was checked on one.)
  EXPECT_LE(most_kb, 8192u) << "largest resident part of the two mappings of the 64 MB file";
  EXPECT_LE(mapped_resident_kb(path), 1024u) << "once both have read to the end";
}

INSTANTIATE_TEST_SUITE_P(CrcChecked, Residency, ::testing::Bool());

class RoundTrip : public ::testing::TestWithParam<McapCompression> {};

TEST_P(RoundTrip, EveryMessageComesBackInOrder) {
  test::TempDir dir("mcap_rt");
  const auto w = write_file(dir.file("rt.mcap"), GetParam(), 500);
  McapReader r;
  std::string error;
  ASSERT_TRUE(r.open(dir.file("rt.mcap"), error)) << error;
  EXPECT_TRUE(r.summary().usable());
  EXPECT_EQ(r.summary().message_count, 500u);
  EXPECT_EQ(r.summary().chunk_count, w.chunks.size());
  EXPECT_EQ(r.channels().size(), 2u);
  ASSERT_NE(r.schema(1), nullptr);
  EXPECT_EQ(r.schema(1)->name, "t/msg/A");
  const auto seq = read_sequences(r);
  ASSERT_EQ(seq.size(), 500u);
  for (std::uint32_t i = 0; i < 500; ++i) EXPECT_EQ(seq[i], i);
  EXPECT_TRUE(r.complete()) << r.stop_reason();
  EXPECT_TRUE(r.issues().empty()) << r.issues().front().what;
  EXPECT_EQ(r.counters().chunks, w.chunks.size());
  // rewind replays the same
  r.rewind();
  EXPECT_EQ(read_sequences(r).size(), 500u);
}

INSTANTIATE_TEST_SUITE_P(Compression, RoundTrip,
                         ::testing::Values(McapCompression::kNone, McapCompression::kLz4,
                                           McapCompression::kZstd));

TEST(Truncation, ACutFileYieldsEveryCompleteChunkAndSaysWhere) {
  test::TempDir dir("mcap_cut");
  const std::string full_path = dir.file("full.mcap");
  const auto w = write_file(full_path, McapCompression::kLz4, 300, 1024);
  ASSERT_GE(w.chunks.size(), 10u);
  const auto full = test::slurp(full_path);
  const std::size_t header_end = 8 + 9 + 4 + 4 + 5;  // magic + Header("", "posed")

  // Every byte through the first two chunks, then a prime stride, then the tail byte by byte.
  std::vector<std::size_t> cuts;
  const std::size_t dense_end = static_cast<std::size_t>(w.chunks[1].index_end_offset) + 8;
  for (std::size_t c = 0; c < dense_end; ++c) cuts.push_back(c);
  for (std::size_t c = dense_end; c < full.size() - 200; c += 97) cuts.push_back(c);
  for (std::size_t c = full.size() - 200; c < full.size(); ++c) cuts.push_back(c);

  std::size_t data_end = static_cast<std::size_t>(w.chunks.back().index_end_offset);
  for (std::size_t cut : cuts) {
    const std::span<const std::byte> bytes(full.data(), cut);
    McapReader r;
    std::string error;
    const bool opened = r.open_bytes(bytes, error);
    if (cut < header_end) {
      EXPECT_FALSE(opened) << "cut " << cut;
      EXPECT_FALSE(error.empty());
      continue;
    }
    ASSERT_TRUE(opened) << "cut " << cut << ": " << error;
    // Expected: the messages of every chunk that ends at or before the cut.
    std::uint64_t expected = 0;
    for (const auto& c : w.chunks) {
      if (c.start_offset + c.chunk_length <= cut) expected += c.message_count;
    }
    const auto seq = read_sequences(r);
    ASSERT_EQ(seq.size(), expected) << "cut at " << cut;
    for (std::size_t i = 0; i < seq.size(); ++i) ASSERT_EQ(seq[i], i);
    if (cut <= data_end) {
      EXPECT_FALSE(r.complete()) << "cut " << cut;
      EXPECT_NE(r.stop_reason().find("offset"), std::string::npos) << r.stop_reason();
      EXPECT_LE(r.offset(), cut);
      EXPECT_FALSE(r.summary().usable());
    } else {
      // Cut inside the summary: the data is whole; the missing footer is reported.
      EXPECT_EQ(seq.size(), 300u);
      EXPECT_FALSE(r.summary().footer_found);
      EXPECT_FALSE(r.issues().empty());
    }
  }
}

TEST(MappedFileRelease, ReleasedPagesReadBackTheSameBytes) {
  // The MCAP reader releases what it has read (a long replay's RSS would grow by the file);
  // a message handed out before may still point there, and must read the same.
  test::TempDir dir("mapped_release");
  std::vector<std::byte> bytes(3u << 20);
  for (std::size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = static_cast<std::byte>(i * 7 + i / 4099);
  test::spit(dir.file("f.bin"), bytes);
  MappedFile file;
  std::string error;
  ASSERT_TRUE(file.open(dir.file("f.bin"), error)) << error;
  ASSERT_EQ(file.bytes().size(), bytes.size());
  ASSERT_EQ(std::memcmp(file.bytes().data(), bytes.data(), bytes.size()), 0);
  file.release(100, bytes.size() - 100);  // partial pages at both ends are kept
  file.release(0, bytes.size() * 2);      // beyond the end: clamped
  EXPECT_EQ(std::memcmp(file.bytes().data(), bytes.data(), bytes.size()), 0);
}

TEST(BadInput, WrongMagicIsRefusedWithTheOffset) {
  std::vector<std::byte> junk(64, std::byte{0x42});
  McapReader r;
  std::string error;
  EXPECT_FALSE(r.open_bytes(junk, error));
  EXPECT_NE(error.find("magic"), std::string::npos) << error;
  EXPECT_NE(error.find("offset 0"), std::string::npos) << error;
  test::TempDir dir("mcap_missing");
  EXPECT_FALSE(r.open(dir.file("nope.mcap"), error));
  EXPECT_NE(error.find("nope.mcap"), std::string::npos) << error;
}

TEST(BadInput, AChunkWithABadCrcIsSkippedAndTheRestIsRead) {
  test::TempDir dir("mcap_crc");
  const auto w = write_file(dir.file("f.mcap"), McapCompression::kNone, 100, 1024);
  auto bytes = test::slurp(dir.file("f.mcap"));
  ASSERT_GE(w.chunks.size(), 3u);
  const auto& victim = w.chunks[1];
  // Flip a payload byte in the middle of chunk 1's records.
  bytes[static_cast<std::size_t>(victim.start_offset + victim.chunk_length - 30)] ^= std::byte{1};
  McapReader r;
  std::string error;
  ASSERT_TRUE(r.open_bytes(bytes, error)) << error;
  std::size_t n = 0;
  McapMessage m;
  while (r.next(m)) ++n;
  EXPECT_EQ(n, 100 - victim.message_count);
  EXPECT_EQ(r.counters().chunks_bad, 1u);
  EXPECT_FALSE(r.complete());
  bool named = false;
  for (const auto& i : r.issues()) {
    named = named || (i.offset == victim.start_offset && i.what.find("CRC") != std::string::npos);
  }
  EXPECT_TRUE(named) << "an issue naming the chunk's offset";
  // The data-section CRC also notices.
  bool data_crc = false;
  for (const auto& i : r.issues())
    data_crc = data_crc || i.what.find("data section") != i.what.npos;
  EXPECT_TRUE(data_crc);
}

TEST(ChunkCache, ReadersOfOneFileShareDecompressedChunksAndNeverADamagedOne) {
  test::TempDir dir("mcap_cache");
  const auto w = write_file(dir.file("f.mcap"), McapCompression::kLz4, 400, 1024);
  auto bytes = test::slurp(dir.file("f.mcap"));
  ASSERT_GE(w.chunks.size(), 4u);
  const auto& victim = w.chunks[2];
  // A byte in the middle of its compressed records: it no longer decompresses, or fails its CRC.
  bytes[static_cast<std::size_t>(victim.start_offset + victim.chunk_length / 2 + 20)] ^=
      std::byte{0x55};
  McapReaderOptions options;
  options.chunk_cache = std::make_shared<McapChunkCache>(4096);  // a few of its 1 kB chunks
  McapReader first, second;
  std::string error;
  ASSERT_TRUE(first.open_bytes(bytes, error, options)) << error;
  ASSERT_TRUE(second.open_bytes(bytes, error, options)) << error;
  // Side by side, as a replay's streams read: every message of both, from one decompression per
  // good chunk; the damaged chunk is reported by each reader, not handed from one to the other.
  std::vector<std::uint32_t> a, b;
  McapMessage m;
  for (bool more_a = true, more_b = true; more_a || more_b;) {
    if (more_a && (more_a = first.next(m))) a.push_back(m.sequence);
    if (more_b && (more_b = second.next(m))) {
      b.push_back(m.sequence);
      const auto want = payload_for(m.sequence);
      ASSERT_TRUE(m.data.size() == want.size() &&
                  std::memcmp(m.data.data(), want.data(), want.size()) == 0);
    }
  }
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.size(), 400u - victim.message_count);
  EXPECT_EQ(first.counters().chunks_bad, 1u);
  EXPECT_EQ(second.counters().chunks_bad, 1u);
  EXPECT_EQ(first.counters().chunks + second.counters().chunks, 2 * (w.chunks.size() - 1));
  const McapChunkCacheCounters c = options.chunk_cache->counters();
  EXPECT_EQ(c.hits, w.chunks.size() - 1) << "the second reader found every good chunk";
  EXPECT_EQ(c.misses, w.chunks.size() + 1) << "the first reader's, and the damaged one twice";
  // The data section's CRC is folded once, by the reader that read first, and it notices.
  const auto data_crc_issues = [](const McapReader& r) {
    int n = 0;
    for (const auto& i : r.issues()) n += i.what.find("data section CRC") != std::string::npos;
    return n;
  };
  EXPECT_EQ(data_crc_issues(first), 1);
  EXPECT_EQ(data_crc_issues(second), 0);
}

TEST(ChunkCache, AnEvictedChunksBufferIsReusedOnlyOnceNoReaderWalksIt) {
  McapChunkCache cache(1);  // the newest chunk only
  auto first = cache.buffer();
  first->resize(1000);
  const std::vector<std::byte>* const first_storage = first.get();
  cache.add(0, std::move(first));
  McapChunkCache::Chunk walked = cache.find(0);  // a reader walks the chunk at offset 0
  auto second = cache.buffer();
  EXPECT_NE(second.get(), first_storage);
  cache.add(100, std::move(second));  // evicts offset 0, which the reader still walks
  auto third = cache.buffer();
  EXPECT_NE(third.get(), first_storage) << "handed out while a reader walks it";
  EXPECT_EQ(cache.buffers_reused(), 0u);
  walked.reset();  // the reader moves on: the storage is free for the next chunk
  auto fourth = cache.buffer();
  EXPECT_EQ(fourth.get(), first_storage);
  EXPECT_GE(fourth->capacity(), 1000u) << "its allocation kept";
  EXPECT_EQ(cache.buffers_reused(), 1u);
}

TEST(BadInput, ASummaryWithABadCrcFallsBackToTheScan) {
  test::TempDir dir("mcap_sumcrc");
  write_file(dir.file("f.mcap"), McapCompression::kLz4, 50);
  auto bytes = test::slurp(dir.file("f.mcap"));
  bytes[bytes.size() - 8 - 4] ^= std::byte{0xFF};  // the stored summary CRC
  McapReader r;
  std::string error;
  ASSERT_TRUE(r.open_bytes(bytes, error)) << error;
  EXPECT_TRUE(r.summary().footer_found);
  EXPECT_FALSE(r.summary().usable());
  ASSERT_FALSE(r.issues().empty());
  EXPECT_NE(r.issues().front().what.find("summary CRC"), std::string::npos);
  EXPECT_EQ(read_sequences(r).size(), 50u);
  EXPECT_TRUE(r.complete());
}

// Builds a file by hand: magic, Header, the given records, DataEnd (CRC 0), Footer(0,0,0), magic.
std::vector<std::byte> handmade(const std::vector<std::byte>& middle) {
  std::vector<std::byte> f;
  mcap::Out o(f);
  o.put(mcap::kMagic.data(), 8);
  auto at = o.begin_record(mcap::Op::kHeader);
  o.str("");
  o.str("hand");
  o.finish_record(at);
  o.bytes(middle);
  at = o.begin_record(mcap::Op::kDataEnd);
  o.u32(0);
  o.finish_record(at);
  at = o.begin_record(mcap::Op::kFooter);
  o.u64(0);
  o.u64(0);
  o.u32(0);
  o.finish_record(at);
  o.put(mcap::kMagic.data(), 8);
  return f;
}

void channel(mcap::Out& o, std::uint16_t id, std::uint16_t schema, const char* topic) {
  auto at = o.begin_record(mcap::Op::kChannel);
  o.u16(id);
  o.u16(schema);
  o.str(topic);
  o.str("posed-raw");
  o.u32(0);
  o.finish_record(at);
}

void message(mcap::Out& o, std::uint16_t ch, std::uint32_t seq, const char* text) {
  auto at = o.begin_record(mcap::Op::kMessage);
  o.u16(ch);
  o.u32(seq);
  o.u64(seq);
  o.u64(seq);
  o.put(text, std::strlen(text));
  o.finish_record(at);
}

TEST(BadInput, UnknownOpcodesAreSkippedAsTheSpecSays) {
  std::vector<std::byte> mid;
  mcap::Out o(mid);
  channel(o, 1, 0, "/x");
  message(o, 1, 0, "first");
  auto at = o.begin_record(static_cast<mcap::Op>(0x80));  // application extension
  o.u64(123);
  o.finish_record(at);
  at = o.begin_record(static_cast<mcap::Op>(0x42));  // reserved, not yet defined
  o.finish_record(at);
  message(o, 1, 1, "second");
  message(o, 7, 2, "orphan");  // channel 7 is never defined
  const auto file = handmade(mid);
  McapReader r;
  std::string error;
  ASSERT_TRUE(r.open_bytes(file, error)) << error;
  McapMessage m;
  ASSERT_TRUE(r.next(m));
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(m.data.data()), m.data.size()), "first");
  ASSERT_TRUE(r.next(m));
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(m.data.data()), m.data.size()), "second");
  EXPECT_FALSE(r.next(m));
  EXPECT_EQ(r.counters().unknown_records, 2u);
  EXPECT_EQ(r.counters().orphan_messages, 1u);
  EXPECT_TRUE(r.summary().footer_found);
  EXPECT_FALSE(r.summary().present);
}

TEST(BadInput, ARewindReadsTheSameMessagesAsTheFirstPass) {
  // A message before its Channel record (a broken writer, no summary): an orphan in every pass,
  // not only the first, although the reader has learnt the channel by the second (found by
  // mcap_reader_fuzz; a replay loop must replay the same data each time).
  std::vector<std::byte> mid;
  mcap::Out o(mid);
  message(o, 1, 0, "too early");
  channel(o, 1, 0, "/x");
  message(o, 1, 1, "in order");
  const auto file = handmade(mid);
  McapReader r;
  std::string error;
  ASSERT_TRUE(r.open_bytes(file, error)) << error;
  for (int pass = 0; pass < 3; ++pass) {
    McapMessage m;
    ASSERT_TRUE(r.next(m)) << pass;
    EXPECT_EQ(m.sequence, 1u) << pass;
    EXPECT_FALSE(r.next(m)) << pass;
    EXPECT_EQ(r.counters().orphan_messages, static_cast<std::uint64_t>(pass + 1));
    r.rewind();
  }
}

TEST(BadInput, AChannelWithoutItsSchemaIsReportedAndStillRead) {
  std::vector<std::byte> mid;
  mcap::Out o(mid);
  channel(o, 3, 9, "/needs_schema_9");
  message(o, 3, 0, "payload");
  const auto file = handmade(mid);
  McapReader r;
  std::string error;
  ASSERT_TRUE(r.open_bytes(file, error)) << error;
  McapMessage m;
  ASSERT_TRUE(r.next(m));
  EXPECT_EQ(m.channel->schema_id, 9);
  EXPECT_EQ(r.schema(9), nullptr);
  ASSERT_FALSE(r.issues().empty());
  EXPECT_NE(r.issues().front().what.find("schema 9"), std::string::npos);
  EXPECT_EQ(r.issues().front().offset, 8u + 9 + 4 + 4 + 4);  // the Channel record
}

TEST(BadInput, AChunkWithAnUnknownCompressionIsSkipped) {
  std::vector<std::byte> mid;
  mcap::Out o(mid);
  channel(o, 1, 0, "/x");
  const std::size_t chunk_at = mid.size();
  auto at = o.begin_record(mcap::Op::kChunk);
  o.u64(0);
  o.u64(0);
  o.u64(4);
  o.u32(0);
  o.str("brotli");
  o.u64(4);
  o.u32(0xDEADBEEF);
  o.finish_record(at);
  message(o, 1, 5, "after");
  const auto file = handmade(mid);
  McapReader r;
  std::string error;
  ASSERT_TRUE(r.open_bytes(file, error)) << error;
  McapMessage m;
  ASSERT_TRUE(r.next(m));
  EXPECT_EQ(m.sequence, 5u);
  EXPECT_EQ(r.counters().chunks_bad, 1u);
  ASSERT_FALSE(r.issues().empty());
  EXPECT_NE(r.issues().front().what.find("brotli"), std::string::npos);
  EXPECT_EQ(r.issues().front().offset, 8u + 9 + 4 + 4 + 4 + chunk_at);
}

TEST(BadInput, RecordLengthsBeyondTheFileStopCleanly) {
  std::vector<std::byte> mid;
  mcap::Out o(mid);
  channel(o, 1, 0, "/x");
  message(o, 1, 0, "ok");
  o.u8(0x05);
  o.u64(~0ull);  // absurd length
  const auto file = handmade(mid);
  McapReader r;
  std::string error;
  ASSERT_TRUE(r.open_bytes(file, error)) << error;
  McapMessage m;
  ASSERT_TRUE(r.next(m));
  EXPECT_FALSE(r.next(m));
  EXPECT_FALSE(r.complete());
  EXPECT_NE(r.stop_reason().find("truncated Message record"), std::string::npos) << r.stop_reason();
}

}  // namespace
}  // namespace posed::drivers::recording
