#pragma once
// Reads MCAP files (mcap.dev spec) by a linear scan of the data section, the way a streaming
// reader does, so a file cut short by a crash or power loss yields every complete chunk and then
// says where it stopped. When the Footer and summary are present and their CRC holds, the
// summary's Channels/Schemas/Statistics are loaded first (and chunks wholly before
// `min_log_time_ns` are skipped without decompressing them); when they are missing or bad the
// reader says so and relies on the scan alone.
//
// Bad input never throws: every problem becomes an McapIssue with its file offset; reading goes
// on wherever the format allows (unknown opcodes are skipped as the spec says; a chunk with a bad
// CRC or an unknown compression is skipped) and stops at the first record cut short.

#include <bitset>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "drivers/recording/crc32.hpp"
#include "drivers/recording/mapped_file.hpp"
#include "drivers/recording/mcap_chunk_cache.hpp"

namespace posed::drivers::recording {

struct McapSchemaRecord {
  std::uint16_t id = 0;
  std::string name;      ///< e.g. "geometry_msgs/msg/PoseStamped"
  std::string encoding;  ///< e.g. "ros2msg", "ros1msg"; "" for none
  std::vector<std::byte> data;
};

struct McapChannelRecord {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  ///< 0: no schema
  std::string topic;
  std::string message_encoding;  ///< e.g. "cdr", "ros1", "posed-raw"
  std::map<std::string, std::string> metadata;
};

/// One message; `data` is valid until the next call to next() or rewind().
struct McapMessage {
  /// the channel record (never null for a returned message)
  const McapChannelRecord* channel = nullptr;
  std::uint32_t sequence = 0;
  std::uint64_t log_time_ns = 0;      ///< [ns]
  std::uint64_t publish_time_ns = 0;  ///< [ns]
  std::span<const std::byte> data;
  /// file offset of the record holding the message (its Chunk, or itself) [B]
  std::uint64_t record_offset = 0;
};

/// One problem found in the file.
struct McapIssue {
  std::uint64_t offset = 0;  ///< file offset of the offending record [B]
  std::string what;          ///< "truncated Chunk record: needs 1048600 B, 5120 B left"
};

/// A record whose opcode this reader does not know (or that does not belong where it was found),
/// skipped as the spec says: application extensions (0x80-0xFF), opcodes of a newer spec.
struct McapUnknownRecord {
  std::uint64_t offset = 0;  ///< file offset of the record, or of the Chunk holding it [B]
  /// position in the Chunk's uncompressed records; -1 for a record of the data section [B]
  std::int64_t chunk_byte = -1;
  std::uint8_t opcode = 0;
  std::uint64_t length = 0;  ///< content length [B]
};

struct McapMetadataRecord {
  std::string name;
  std::map<std::string, std::string> entries;
};

/// What the summary section said (valid only when `present && crc_ok && parsed`).
struct McapSummaryInfo {
  bool footer_found = false;  ///< trailing magic and Footer record present
  bool present = false;       ///< the Footer points at a summary section
  bool crc_ok = false;        ///< summary CRC matched (or was 0: not provided)
  bool parsed = false;        ///< every summary record parsed
  bool has_statistics = false;
  std::uint64_t message_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time_ns = 0;
  std::uint64_t message_end_time_ns = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
  std::uint64_t chunk_index_count = 0;
  bool usable() const { return present && crc_ok && parsed; }
};

struct McapReaderCounters {
  std::uint64_t messages = 0;             ///< messages returned
  std::uint64_t chunks = 0;               ///< chunks decoded
  std::uint64_t chunks_skipped_time = 0;  ///< chunks before min_log_time_ns, not decoded
  std::uint64_t chunks_bad = 0;           ///< bad CRC, unknown compression, undecodable
  std::uint64_t unknown_records = 0;      ///< unknown opcodes skipped
  std::uint64_t bad_records = 0;          ///< records whose fields did not parse
  std::uint64_t orphan_messages = 0;      ///< messages on a channel never defined
  std::uint64_t issues = 0;               ///< all issues (only the first 100 are kept)
  std::uint64_t bytes_scanned = 0;        ///< [B]
};

struct McapReaderOptions {
  /// check chunk CRCs, the data-section CRC and the summary CRC (the data-section CRC by one
  /// reader of those sharing a chunk_cache: McapChunkCache::claim_data_crc)
  bool verify_crcs = true;
  /// skip whole chunks that end before this log time (only when the summary is usable, so no
  /// Channel record can be lost with them) [ns]
  std::uint64_t min_log_time_ns = 0;
  /// refuse chunks that claim more than this when decompressed [B]
  std::uint64_t max_chunk_bytes = 512ull << 20;
  /// compressed chunks decompressed by another reader of the same file (null: none shared)
  std::shared_ptr<McapChunkCache> chunk_cache;
};

class McapReader {
 public:
  McapReader();
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  /// Maps `path` read-only and checks the magic and Header. false + `error` ("mcap PATH: ...")
  /// when it is not an MCAP file at all; a damaged body is not an open error (see issues()).
  bool open(const std::string& path, std::string& error, McapReaderOptions options = {});
  /// The same over bytes the caller keeps alive (tests, fuzzing).
  bool open_bytes(std::span<const std::byte> bytes, std::string& error,
                  McapReaderOptions options = {});

  /// The next message in file order; false at the end of the data (see complete()/issues()).
  bool next(McapMessage& out);
  /// Starts again from the first record (replay loops).
  void rewind();

  /// true once the scan reached DataEnd (or a Footer) with no issue on the way
  bool complete() const { return complete_; }
  /// where the scan is / stopped: the offset of the next unread record [B]
  std::uint64_t offset() const { return pos_; }
  std::uint64_t file_size_bytes() const { return file_.size(); }
  /// One sentence: "" when complete, else why and where reading stopped.
  std::string stop_reason() const { return stop_reason_; }

  const std::map<std::uint16_t, McapChannelRecord>& channels() const { return channels_; }
  const std::map<std::uint16_t, McapSchemaRecord>& schemas() const { return schemas_; }
  const McapSchemaRecord* schema(std::uint16_t id) const;
  const std::vector<McapIssue>& issues() const { return issues_; }
  /// the first 100 records skipped for their opcode (counters().unknown_records counts all)
  const std::vector<McapUnknownRecord>& unknown_records() const { return unknown_records_; }
  const McapSummaryInfo& summary() const { return summary_; }
  const std::vector<McapMetadataRecord>& metadata() const { return metadata_; }
  const McapReaderCounters& counters() const { return counters_; }
  const std::string& profile() const { return profile_; }
  const std::string& library() const { return library_; }

 private:
  bool open_common(std::string& error);
  void read_summary();
  bool parse_schema(std::span<const std::byte> body, std::uint64_t offset);
  bool parse_channel(std::span<const std::byte> body, std::uint64_t offset);
  void issue(std::uint64_t offset, std::string what);
  void unknown(std::uint64_t offset, std::int64_t chunk_byte, std::uint8_t opcode,
               std::uint64_t length);
  void stop(std::uint64_t offset, std::string what);
  bool enter_chunk(std::span<const std::byte> body, std::uint64_t offset);
  bool next_in_chunk(McapMessage& out);
  bool decode_message(std::span<const std::byte> body, std::uint64_t offset, McapMessage& out);

  MappedFile mapped_;
  /// the file before this offset was released from memory (next())
  std::uint64_t released_ = 0;
  std::span<const std::byte> file_;
  std::string path_;
  McapReaderOptions options_;

  std::string profile_, library_;
  std::uint64_t data_start_ = 0;  // first record after the Header
  std::uint64_t pos_ = 0;
  bool done_ = false;
  bool complete_ = false;
  std::string stop_reason_;
  Crc32 data_crc_;
  std::uint64_t crc_pos_ = 0;      // bytes [0, crc_pos_) are in data_crc_
  bool verify_data_crc_ = true;    // this reader folds data_crc_
  bool data_crc_decided_ = false;  // verify_data_crc_ is set (on the first next())

  // the chunk being walked
  std::span<const std::byte> chunk_records_;
  std::size_t chunk_pos_ = 0;
  std::uint64_t chunk_offset_ = 0;
  std::vector<std::byte> chunk_buf_;
  /// the chunk being walked when it came from (or went to) options_.chunk_cache
  McapChunkCache::Chunk shared_chunk_;
  void* zstd_ctx_ = nullptr;
  void* lz4_ctx_ = nullptr;

  std::map<std::uint16_t, McapChannelRecord> channels_;
  std::map<std::uint16_t, McapSchemaRecord> schemas_;
  // Which channels a message may use: those of a usable summary, and those whose Channel record
  // this pass has read. Records learnt in an earlier pass stay in channels_ (McapMessage points
  // into it) but do not count, so every pass over a damaged file reads the same messages.
  std::bitset<65536> summary_channels_;
  std::bitset<65536> seen_channels_;
  std::vector<McapMetadataRecord> metadata_;
  std::vector<McapIssue> issues_;
  std::vector<McapUnknownRecord> unknown_records_;
  McapSummaryInfo summary_;
  McapReaderCounters counters_;
};

}  // namespace posed::drivers::recording
