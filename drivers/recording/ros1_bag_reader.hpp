#pragma once
// Reads ROS 1 bags, format 2.0 (wiki.ros.org/Bags/Format/2.0; records: ros1_bag_records.hpp,
// chunk compression none/bz2/lz4: ros1_chunk.hpp), message by message in receive-time order.
//
// Two ways through a file:
//  - indexed: when the bag header's index_pos leads to the Connection and ChunkInfo records that
//    `rosbag` writes when it closes a bag, and every chunk's IndexData records agree with them,
//    the messages of all chunks are merged by receive time from the index (stable: ties keep
//    file order), and each chunk is decompressed when first needed;
//  - sequential: otherwise (a bag whose recorder was killed has index_pos 0; one cut short has
//    its index past the end), records are scanned from the start. Messages come chunk by chunk,
//    each chunk's sorted by receive time, which is the order `rosbag record` writes them in.
//
// Bad input never throws and costs only what it damages: wrong magic is an open() error; an
// unknown op is skipped; a chunk with an unknown compression or that does not decompress, an
// index entry that does not point at a message, a message on a connection never defined are
// each skipped with a BagIssue naming the byte offset; a record cut short ends the scan there,
// after everything before it was delivered, and stop_reason() says where.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "drivers/recording/mapped_file.hpp"
#include "drivers/recording/ros1_chunk.hpp"

namespace posed::drivers::recording::ros1 {

/// One connection (a publisher's topic as rosbag recorded it).
struct BagConnection {
  std::uint32_t id = 0;
  std::string topic;
  std::string type;    ///< e.g. "sensor_msgs/PointCloud2"
  std::string md5sum;  ///< of the message definition, as ROS 1 computes it
  /// the full text of the definition with its dependencies (gendeps --cat), as recorded
  std::string message_definition;
  std::string callerid;  ///< the publishing node; empty when not recorded
  bool latching = false;
  /// file offset of the first Connection record seen for it [B]
  std::uint64_t record_offset = 0;
};

/// One message. `data` is valid until the next call to next().
struct BagMessage {
  const BagConnection* connection = nullptr;
  /// when rosbag received it, ROS time (the recording machine's clock, or /clock) [ns]
  std::uint64_t receive_time_ns = 0;
  /// the serialized message (ROS 1 serialization; decoders in ros1_messages.hpp)
  std::span<const std::byte> data;
  /// file offset of the Chunk record holding it, or of the record itself outside chunks [B]
  std::uint64_t chunk_offset = 0;
  /// offset of its MessageData record inside the uncompressed chunk [B]
  std::uint64_t offset_in_chunk = 0;
};

struct BagIssue {
  std::uint64_t offset = 0;  ///< file offset of the offending record [B]
  std::string what;
};

/// A chunk as the index (ChunkInfo) or the scan saw it.
struct BagChunkSummary {
  std::uint64_t offset = 0;              ///< file offset of the Chunk record [B]
  std::string compression;               ///< "none", "bz2", "lz4", or what the file said
  std::uint64_t compressed_bytes = 0;    ///< [B]
  std::uint64_t uncompressed_bytes = 0;  ///< [B]
  std::uint64_t start_time_ns = 0;       ///< earliest receive time (from ChunkInfo; 0 when unknown)
  std::uint64_t end_time_ns = 0;         ///< latest receive time [ns]
  std::uint64_t message_count = 0;
};

struct BagReaderCounters {
  std::uint64_t messages = 0;           ///< messages returned
  std::uint64_t chunks = 0;             ///< chunks decompressed
  std::uint64_t chunks_bad = 0;         ///< unknown compression, undecodable, too large
  std::uint64_t unknown_records = 0;    ///< records with an op this reader does not know
  std::uint64_t bad_records = 0;        ///< records whose header fields did not parse
  std::uint64_t orphan_messages = 0;    ///< messages on a connection never defined
  std::uint64_t bad_index_entries = 0;  ///< index entries that did not lead to a message
  std::uint64_t issues = 0;             ///< all issues (only the first 100 are kept)
};

struct BagReaderOptions {
  /// use the index when it is intact (false: always scan sequentially)
  bool use_index = true;
  /// refuse chunks that claim more than this uncompressed [B]
  std::uint64_t max_chunk_bytes = 1ull << 30;
  /// decompressed chunks kept at once, for bags whose chunks overlap in time [1]
  std::size_t chunk_cache = 4;
  /// called as reading advances through the file: (bytes read so far, file size) [B]
  std::function<void(std::uint64_t, std::uint64_t)> progress;
};

class BagReader {
 public:
  BagReader();
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  /// Maps `path` read-only, checks the magic and the bag header, and loads the index when it is
  /// intact. false + `error` ("bag PATH: ...") only when the file is not a ROS 2.0 bag at all.
  bool open(const std::string& path, std::string& error, BagReaderOptions options = {});
  /// The same over bytes the caller keeps alive (tests, fuzzing).
  bool open_bytes(std::span<const std::byte> bytes, std::string& error,
                  BagReaderOptions options = {});

  /// The next message in receive-time order; false at the end (see complete()/stop_reason()).
  bool next(BagMessage& out);

  /// true when messages come from the index (see the file comment)
  bool indexed() const { return indexed_; }
  /// true once every message was read and nothing was wrong on the way
  bool complete() const { return done_ && counters_.issues == 0; }
  /// "" or, in one sentence, why and where reading stopped early
  const std::string& stop_reason() const { return stop_reason_; }

  /// Connections by id: all of them after open() when indexed, else as the scan meets them.
  const std::map<std::uint32_t, BagConnection>& connections() const { return connections_; }
  /// Chunks: all of them after open() when indexed, else as the scan meets them.
  const std::vector<BagChunkSummary>& chunks() const { return chunks_; }
  /// Messages per connection according to the index (empty when not indexed).
  const std::map<std::uint32_t, std::uint64_t>& indexed_counts() const { return indexed_counts_; }
  const std::vector<BagIssue>& issues() const { return issues_; }
  const BagReaderCounters& counters() const { return counters_; }
  std::uint64_t file_size_bytes() const { return file_.size(); }
  /// the bag header's fields (0 when absent)
  std::uint64_t index_pos() const { return index_pos_; }
  std::uint32_t header_conn_count() const { return header_conn_count_; }
  std::uint32_t header_chunk_count() const { return header_chunk_count_; }

 private:
  struct IndexEntry {
    std::uint64_t time_ns = 0;
    std::uint32_t chunk = 0;   // index into chunks_
    std::uint32_t offset = 0;  // of the MessageData record in the uncompressed chunk
    std::uint32_t conn = 0;
  };
  struct ScanEntry {
    std::uint64_t time_ns = 0;
    std::uint64_t offset = 0;  // of the MessageData record in the current chunk
  };
  struct CachedChunk {
    std::uint32_t chunk = 0;
    bool ok = false;
    std::span<const std::byte> records;  // into `buffer`, or into the file when uncompressed
    std::vector<std::byte> buffer;
    std::uint64_t last_use = 0;
  };

  bool open_common(std::string& error);
  bool load_index(std::string& why);
  bool index_chunk(std::uint32_t chunk, std::uint64_t& end_offset, std::string& why);
  bool next_indexed(BagMessage& out);
  bool next_sequential(BagMessage& out);
  bool enter_chunk(std::span<const std::byte> header_fields_bytes, std::uint64_t offset,
                   std::span<const std::byte> data);
  const CachedChunk* chunk_records(std::uint32_t chunk);
  bool decompress(std::uint64_t offset, std::span<const std::byte> header,
                  std::span<const std::byte> data, std::vector<std::byte>& buffer,
                  std::span<const std::byte>& records, BagChunkSummary* summary);
  bool add_connection(std::span<const std::byte> header, std::span<const std::byte> data,
                      std::uint64_t offset);
  bool message_at(std::span<const std::byte> records, std::uint64_t offset_in_chunk,
                  std::uint64_t chunk_offset, std::uint32_t expected_conn, BagMessage& out);
  void issue(std::uint64_t offset, std::string what);
  void stop(std::uint64_t offset, std::string what);
  void report_progress(std::uint64_t offset);

  MappedFile mapped_;
  std::span<const std::byte> file_;
  std::string path_;
  BagReaderOptions options_;
  ChunkDecompressor decompressor_;

  std::uint64_t index_pos_ = 0;
  std::uint32_t header_conn_count_ = 0;
  std::uint32_t header_chunk_count_ = 0;
  std::uint64_t data_start_ = 0;  // first record after the bag header

  bool indexed_ = false;
  bool index_unusable_ = false;  // the header points at an index that is not (all) there
  bool done_ = false;
  std::string stop_reason_;

  // indexed reading
  std::vector<IndexEntry> entries_;
  std::size_t next_entry_ = 0;
  std::vector<CachedChunk> cache_;
  std::uint64_t use_clock_ = 0;
  std::vector<bool> chunk_failed_;

  // sequential reading
  std::uint64_t pos_ = 0;
  std::uint64_t chunk_offset_ = 0;  // of the chunk being walked
  std::span<const std::byte> chunk_records_;
  std::vector<std::byte> chunk_buffer_;
  std::vector<ScanEntry> scan_entries_;
  std::size_t next_scan_entry_ = 0;

  std::map<std::uint32_t, BagConnection> connections_;
  std::vector<BagChunkSummary> chunks_;
  std::map<std::uint32_t, std::uint64_t> indexed_counts_;
  std::vector<BagIssue> issues_;
  BagReaderCounters counters_;
  std::uint64_t progress_reported_ = 0;
};

}  // namespace posed::drivers::recording::ros1
