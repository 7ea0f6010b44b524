#pragma once
// Writes MCAP files (mcap.dev spec): Header, then Chunks (Schema/Channel/Message records, lz4 or
// zstd compressed, with the CRC of the uncompressed records) each followed by its MessageIndex
// records, Metadata, DataEnd (CRC of the data section), then the summary (Schemas, Channels,
// Statistics, ChunkIndexes, MetadataIndexes), SummaryOffsets and the Footer (summary CRC).
//
// Crash safety: Schema and Channel records go into the chunk where they are first needed, and a
// chunk reaches the file (one write()) only when complete, so a file cut at any byte still holds
// every complete chunk and a linear reader recovers them (McapReader does).
//
// Single-threaded: the Recorder owns one from its writer thread.

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/recording/crc32.hpp"

namespace posed::drivers::recording {

enum class McapCompression : std::uint8_t { kNone, kLz4, kZstd };

/// The spec's compression string: "", "lz4" or "zstd".
std::string_view to_string(McapCompression c);
/// Parses "none"/"", "lz4", "zstd"; false for anything else.
bool parse_compression(std::string_view text, McapCompression& out);

struct McapWriterOptions {
  McapCompression compression = McapCompression::kLz4;
  /// a chunk is closed once its uncompressed records reach this size [B]
  std::size_t chunk_size_bytes = 1u << 20;
  /// Header profile: "" (mixed encodings), "ros1" or "ros2" (spec, "Profiles")
  std::string profile;
  /// Header library: who wrote the file
  std::string library = "posed";
  /// fsync after every N chunks (0: only when closing, if fsync_on_close)
  std::uint32_t fsync_every_chunks = 0;
  bool fsync_on_close = true;
  /// zstd level (1 = fastest); lz4 uses its default fast mode
  int zstd_level = 1;
};

/// Where one chunk went, as recorded in its ChunkIndex (exposed for tests and tools).
struct McapChunkInfo {
  std::uint64_t start_offset = 0;      ///< file offset of the Chunk record [B]
  std::uint64_t chunk_length = 0;      ///< Chunk record incl. opcode and length [B]
  std::uint64_t index_end_offset = 0;  ///< end of its MessageIndex records [B]
  std::uint64_t message_count = 0;
  std::uint64_t message_start_time_ns = 0;  ///< earliest log time [ns]
  std::uint64_t message_end_time_ns = 0;    ///< latest log time [ns]
  std::uint64_t compressed_size_bytes = 0;
  std::uint64_t uncompressed_size_bytes = 0;
  std::string compression;
  /// channel id -> file offset of its MessageIndex record
  std::map<std::uint16_t, std::uint64_t> message_index_offsets;
};

class McapWriter {
 public:
  McapWriter() = default;
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;
  ~McapWriter();

  /// Creates (truncates) `path` and writes the magic and Header. On failure returns false and
  /// sets `error` ("mcap PATH: reason").
  bool open(const std::string& path, const McapWriterOptions& options, std::string& error);

  /// Registers a schema; returns its id (> 0), or 0 when not open.
  std::uint16_t add_schema(std::string_view name, std::string_view encoding,
                           std::span<const std::byte> data);
  /// Registers a channel (`schema_id` 0: no schema); returns its id, or 0xFFFF when full/closed.
  std::uint16_t add_channel(std::string_view topic, std::string_view message_encoding,
                            std::uint16_t schema_id,
                            const std::map<std::string, std::string>& metadata);
  /// Appends a Message record to the current chunk (closing the chunk when it is full).
  bool write_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                     std::uint64_t publish_time_ns, std::span<const std::byte> data);
  /// A Metadata record in the data section, indexed in the summary.
  bool write_metadata(std::string_view name, const std::map<std::string, std::string>& entries);
  /// Closes the current chunk now (the Recorder does this on a timer so slow streams reach disk).
  bool flush_chunk();
  /// Finishes the chunk, writes DataEnd, the summary and the Footer, fsyncs (per options) and
  /// closes. Returns false (and error()) if any write failed. Idempotent.
  bool close();

  bool is_open() const { return fd_ >= 0; }
  /// the first write error ("mcap PATH: write: No space left on device"), or empty
  const std::string& error() const { return error_; }
  /// bytes in the file so far, including the open chunk's pending bytes once written [B]
  std::uint64_t file_size_bytes() const { return file_offset_; }
  /// uncompressed bytes waiting in the open chunk [B]
  std::size_t pending_chunk_bytes() const { return chunk_.size(); }
  std::uint64_t message_count() const { return message_count_; }
  const std::vector<McapChunkInfo>& chunks() const { return chunk_infos_; }
  const std::string& path() const { return path_; }

 private:
  struct ChannelRec {
    std::uint16_t id = 0;
    std::uint16_t schema_id = 0;
    std::string topic, encoding;
    std::map<std::string, std::string> metadata;
    bool in_chunk_file = false;  ///< its record was written into a chunk already
    std::uint64_t message_count = 0;
    /// (log time [ns], offset in the uncompressed chunk [B]) of this chunk's messages
    std::vector<std::pair<std::uint64_t, std::uint64_t>> index;
  };
  struct SchemaRec {
    std::uint16_t id = 0;
    std::string name, encoding;
    std::vector<std::byte> data;
    bool in_chunk_file = false;
  };

  void write_schema_record(std::vector<std::byte>& buf, const SchemaRec& s) const;
  void write_channel_record(std::vector<std::byte>& buf, const ChannelRec& c) const;
  bool write_out(std::span<const std::byte> bytes, bool data_section);
  bool fail(const char* what, int err);
  bool compress_chunk(std::span<const std::byte> in, std::string_view& compression);

  McapWriterOptions options_;
  std::string path_;
  int fd_ = -1;
  std::string error_;
  std::uint64_t file_offset_ = 0;
  Crc32 data_crc_;

  std::vector<SchemaRec> schemas_;    // id = index + 1
  std::vector<ChannelRec> channels_;  // id = index
  std::vector<std::uint16_t> touched_channels_;

  std::vector<std::byte> chunk_;       // uncompressed records of the open chunk
  std::vector<std::byte> compressed_;  // scratch
  std::vector<std::byte> out_;         // scratch for records before write()
  std::uint64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0, chunk_messages_ = 0;
  void* zstd_ctx_ = nullptr;

  std::uint64_t message_count_ = 0;
  std::uint64_t start_ns_ = 0, end_ns_ = 0;
  std::uint32_t chunks_since_sync_ = 0;
  std::vector<McapChunkInfo> chunk_infos_;
  struct MetaIdx {
    std::uint64_t offset = 0, length = 0;
    std::string name;
  };
  std::vector<MetaIdx> metadata_index_;
};

}  // namespace posed::drivers::recording
