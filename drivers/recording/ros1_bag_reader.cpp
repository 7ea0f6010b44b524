#include "drivers/recording/ros1_bag_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>

#include "drivers/recording/ros1_bag_records.hpp"

namespace posed::drivers::recording::ros1 {

namespace {

constexpr std::uint32_t kAnyConnection = std::numeric_limits<std::uint32_t>::max();
constexpr std::size_t kMaxIssuesKept = 100;

std::string fmt(const char* f, auto... args) {
  char buf[320];
  std::snprintf(buf, sizeof buf, f, args...);
  return buf;
}

unsigned long long ull(std::uint64_t v) { return static_cast<unsigned long long>(v); }

/// The first bytes of a file, printable, for "this is not a bag" messages.
std::string printable_prefix(std::span<const std::byte> bytes, std::size_t n) {
  std::string out;
  for (std::size_t i = 0; i < std::min(n, bytes.size()); ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      out += fmt("\\x%02x", c);
    }
  }
  return out;
}

/// "Chunk" for a record whose header parses far enough to say, else "".
std::string op_of(std::span<const std::byte> header) {
  RecordFields f;
  std::string ignored;
  std::uint8_t op = 0;
  if (!f.parse(header, ignored) || !f.get_u8("op", op)) return "";
  return std::string(op_name(op)) + " ";
}

}  // namespace

BagReader::BagReader() = default;
BagReader::~BagReader() = default;

bool BagReader::open(const std::string& path, std::string& error, BagReaderOptions options) {
  path_ = path;
  options_ = std::move(options);
  if (!mapped_.open(path, error, "bag")) return false;
  file_ = mapped_.bytes();
  return open_common(error);
}

bool BagReader::open_bytes(std::span<const std::byte> bytes, std::string& error,
                           BagReaderOptions options) {
  path_ = "(memory)";
  options_ = std::move(options);
  mapped_.close();
  file_ = bytes;
  return open_common(error);
}

void BagReader::issue(std::uint64_t offset, std::string what) {
  ++counters_.issues;
  if (issues_.size() < kMaxIssuesKept) issues_.push_back({offset, std::move(what)});
}

void BagReader::stop(std::uint64_t offset, std::string what) {
  stop_reason_ = what;
  issue(offset, std::move(what));
}

void BagReader::report_progress(std::uint64_t offset) {
  offset = std::min<std::uint64_t>(offset, file_.size());
  if (!options_.progress || offset <= progress_reported_) return;
  progress_reported_ = offset;
  options_.progress(offset, file_.size());
}

bool BagReader::open_common(std::string& error) {
  const std::size_t magic_size = kBagMagic.size();
  if (file_.size() < magic_size || std::memcmp(file_.data(), kBagMagic.data(), magic_size) != 0) {
    const std::string found = printable_prefix(file_, magic_size);
    if (found.rfind("#ROSBAG V", 0) == 0 || found.rfind("#ROSRECORD V", 0) == 0) {
      error = "bag " + path_ + ": unsupported bag format version at offset 0: '" + found +
              "' (only #ROSBAG V2.0 is read; `rosbag reindex`/`rosbag fix` convert older bags)";
    } else {
      error = "bag " + path_ + ": wrong magic at offset 0: expected '#ROSBAG V2.0\\n', found '" +
              found + "'";
    }
    return false;
  }
  data_start_ = pos_ = magic_size;
  BagRecord record;
  std::uint64_t needed = 0;
  if (read_record(file_, magic_size, record, needed) != RecordStatus::kOk) {
    // Not an open error: the file is a bag, cut short before its first record ended.
    stop(magic_size, fmt("truncated bag header record at offset %llu: needs %llu B, %llu B left",
                         ull(magic_size), ull(needed), ull(file_.size() - magic_size)));
    done_ = true;
    return true;
  }
  RecordFields fields;
  std::string why;
  std::uint8_t op = 0;
  if (!fields.parse(record.header, why) || !fields.get_u8("op", op) ||
      op != static_cast<std::uint8_t>(BagOp::kBagHeader)) {
    issue(magic_size, fmt("first record at offset %llu is not a bag header (%s); reading the "
                          "records that follow sequentially",
                          ull(magic_size), why.empty() ? "op differs" : why.c_str()));
    return true;
  }
  fields.get_u64("index_pos", index_pos_);
  fields.get_u32("conn_count", header_conn_count_);
  fields.get_u32("chunk_count", header_chunk_count_);
  data_start_ = pos_ = magic_size + record.size_bytes;

  if (!options_.use_index) return true;
  if (index_pos_ == 0) {
    issue(magic_size, fmt("bag header at offset %llu: index_pos is 0, the bag was never closed "
                          "(recorder stopped early); reading it sequentially",
                          ull(magic_size)));
    return true;
  }
  if (load_index(why)) {
    indexed_ = true;
    return true;
  }
  issue(index_pos_, "index unusable: " + why + "; reading the bag sequentially");
  index_unusable_ = true;
  connections_.clear();
  chunks_.clear();
  entries_.clear();
  indexed_counts_.clear();
  return true;
}

bool BagReader::add_connection(std::span<const std::byte> header, std::span<const std::byte> data,
                               std::uint64_t offset) {
  RecordFields fields;
  std::string why;
  std::uint32_t id = 0;
  if (!fields.parse(header, why) || !fields.get_u32("conn", id)) {
    ++counters_.bad_records;
    issue(offset, fmt("Connection record at offset %llu: %s", ull(offset),
                      why.empty() ? "no conn field" : why.c_str()));
    return false;
  }
  if (connections_.count(id) != 0) return true;  // written in its chunk and again in the index
  RecordFields conn;
  if (!conn.parse(data, why)) {
    ++counters_.bad_records;
    issue(offset, fmt("Connection record at offset %llu (conn %u): bad connection header: %s",
                      ull(offset), id, why.c_str()));
    return false;
  }
  BagConnection c;
  c.id = id;
  c.record_offset = offset;
  std::string_view v;
  if (fields.get_string("topic", v) || conn.get_string("topic", v)) c.topic = v;
  if (conn.get_string("type", v)) c.type = v;
  if (conn.get_string("md5sum", v)) c.md5sum = v;
  if (conn.get_string("message_definition", v)) c.message_definition = v;
  if (conn.get_string("callerid", v)) c.callerid = v;
  if (conn.get_string("latching", v)) c.latching = v == "1";
  if (c.type.empty()) {
    issue(offset, fmt("Connection record at offset %llu (conn %u, topic %s): no message type",
                      ull(offset), id, c.topic.c_str()));
  }
  connections_.emplace(id, std::move(c));
  return true;
}

bool BagReader::load_index(std::string& why) {
  if (index_pos_ < data_start_ || index_pos_ >= file_.size()) {
    why =
        fmt("index_pos %llu is outside the file's records [%llu, %llu): the bag was cut short "
            "or its header is corrupt",
            ull(index_pos_), ull(data_start_), ull(file_.size()));
    return false;
  }
  std::vector<std::map<std::uint32_t, std::uint32_t>> chunk_conn_counts;
  std::uint64_t p = index_pos_;
  while (p < file_.size()) {
    BagRecord record;
    std::uint64_t needed = 0;
    if (read_record(file_, p, record, needed) != RecordStatus::kOk) {
      why = fmt("%srecord at offset %llu is cut short (needs %llu B, %llu B left)",
                op_of(record.header).c_str(), ull(p), ull(needed), ull(file_.size() - p));
      return false;
    }
    RecordFields fields;
    std::uint8_t op = 0;
    if (!fields.parse(record.header, why) || !fields.get_u8("op", op)) {
      why = fmt("record at offset %llu: %s", ull(p), why.empty() ? "no op" : why.c_str());
      return false;
    }
    if (op == static_cast<std::uint8_t>(BagOp::kConnection)) {
      if (!add_connection(record.header, record.data, p)) {
        why = fmt("bad Connection record at offset %llu", ull(p));
        return false;
      }
    } else if (op == static_cast<std::uint8_t>(BagOp::kChunkInfo)) {
      std::uint32_t ver = 0, count = 0;
      BagChunkSummary c;
      if (!fields.get_u32("ver", ver) || ver != 1 || !fields.get_u64("chunk_pos", c.offset) ||
          !fields.get_time_ns("start_time", c.start_time_ns) ||
          !fields.get_time_ns("end_time", c.end_time_ns) || !fields.get_u32("count", count) ||
          record.data.size() != std::uint64_t{count} * 8) {
        why = fmt("ChunkInfo record at offset %llu: missing or malformed fields", ull(p));
        return false;
      }
      std::map<std::uint32_t, std::uint32_t> counts;
      for (std::uint32_t i = 0; i < count; ++i) {
        const std::uint32_t n = load_u32(record.data.data() + 8 * i + 4);
        counts[load_u32(record.data.data() + 8 * i)] += n;
        c.message_count += n;
      }
      chunks_.push_back(c);
      chunk_conn_counts.push_back(std::move(counts));
    } else if (op_name(op) == "unknown") {
      ++counters_.unknown_records;
      issue(p, fmt("unknown op 0x%02x record at offset %llu (%llu B) skipped", op, ull(p),
                   ull(record.size_bytes)));
    } else {
      why = fmt("%s record at offset %llu inside the index section",
                std::string(op_name(op)).c_str(), ull(p));
      return false;
    }
    p += record.size_bytes;
  }
  if (connections_.size() != header_conn_count_ || chunks_.size() != header_chunk_count_) {
    why = fmt("the bag header promises %u connections and %u chunks, the index holds %zu and %zu",
              header_conn_count_, header_chunk_count_, connections_.size(), chunks_.size());
    return false;
  }
  // Chunks in file order; their infos may come in any order.
  std::vector<std::size_t> order(chunks_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return chunks_[a].offset < chunks_[b].offset; });
  std::vector<BagChunkSummary> sorted;
  std::vector<std::map<std::uint32_t, std::uint32_t>> sorted_counts;
  for (const std::size_t i : order) {
    sorted.push_back(chunks_[i]);
    sorted_counts.push_back(std::move(chunk_conn_counts[i]));
  }
  chunks_ = std::move(sorted);
  chunk_failed_.assign(chunks_.size(), false);

  for (std::uint32_t i = 0; i < chunks_.size(); ++i) {
    const std::size_t first = entries_.size();
    std::uint64_t end = 0;
    if (!index_chunk(i, end, why)) return false;
    std::map<std::uint32_t, std::uint32_t> seen;
    for (std::size_t k = first; k < entries_.size(); ++k) ++seen[entries_[k].conn];
    if (seen != sorted_counts[i]) {
      why =
          fmt("the IndexData records after the chunk at offset %llu disagree with its ChunkInfo "
              "(%zu messages indexed, %llu announced)",
              ull(chunks_[i].offset), entries_.size() - first, ull(chunks_[i].message_count));
      return false;
    }
    // File order within the chunk, so the stable sort below keeps ties in file order.
    std::sort(entries_.begin() + static_cast<std::ptrdiff_t>(first), entries_.end(),
              [](const IndexEntry& a, const IndexEntry& b) { return a.offset < b.offset; });
  }
  std::stable_sort(entries_.begin(), entries_.end(),
                   [](const IndexEntry& a, const IndexEntry& b) { return a.time_ns < b.time_ns; });
  for (const IndexEntry& e : entries_) ++indexed_counts_[e.conn];
  return true;
}

bool BagReader::index_chunk(std::uint32_t chunk, std::uint64_t& end_offset, std::string& why) {
  BagChunkSummary& c = chunks_[chunk];
  BagRecord record;
  std::uint64_t needed = 0;
  RecordFields fields;
  std::uint8_t op = 0;
  std::string_view compression;
  std::uint32_t size = 0;
  if (c.offset < data_start_ || c.offset >= index_pos_ ||
      read_record(file_, c.offset, record, needed) != RecordStatus::kOk ||
      !fields.parse(record.header, why) || !fields.get_u8("op", op) ||
      op != static_cast<std::uint8_t>(BagOp::kChunk) ||
      !fields.get_string("compression", compression) || !fields.get_u32("size", size)) {
    why =
        fmt("ChunkInfo points at offset %llu, where there is no valid Chunk record", ull(c.offset));
    return false;
  }
  c.compression = compression;
  c.compressed_bytes = record.data.size();
  c.uncompressed_bytes = size;
  std::uint64_t p = c.offset + record.size_bytes;
  while (p < index_pos_) {
    BagRecord ix;
    RecordFields f;
    if (read_record(file_, p, ix, needed) != RecordStatus::kOk || !f.parse(ix.header, why) ||
        !f.get_u8("op", op)) {
      why = fmt("record at offset %llu after the chunk at offset %llu does not parse", ull(p),
                ull(c.offset));
      return false;
    }
    if (op != static_cast<std::uint8_t>(BagOp::kIndexData)) break;
    std::uint32_t ver = 0, conn = 0, count = 0;
    if (!f.get_u32("ver", ver) || ver != 1 || !f.get_u32("conn", conn) ||
        !f.get_u32("count", count) || ix.data.size() != std::uint64_t{count} * 12) {
      why = fmt("IndexData record at offset %llu: missing or malformed fields", ull(p));
      return false;
    }
    if (connections_.count(conn) == 0) {
      why =
          fmt("IndexData record at offset %llu names connection %u, which the index does not "
              "define",
              ull(p), conn);
      return false;
    }
    for (std::uint32_t k = 0; k < count; ++k) {
      const std::byte* e = ix.data.data() + std::size_t{12} * k;
      const std::uint32_t offset = load_u32(e + 8);
      if (offset >= size) {
        why =
            fmt("IndexData record at offset %llu: entry %u points at +%u, past the chunk's "
                "%u B",
                ull(p), k, offset, size);
        return false;
      }
      entries_.push_back({load_time_ns(e), chunk, offset, conn});
    }
    p += ix.size_bytes;
  }
  end_offset = p;
  return true;
}

bool BagReader::decompress(std::uint64_t offset, std::span<const std::byte> header,
                           std::span<const std::byte> data, std::vector<std::byte>& buffer,
                           std::span<const std::byte>& records, BagChunkSummary* summary) {
  RecordFields fields;
  std::string why;
  std::string_view compression_name;
  std::uint32_t size = 0;
  if (!fields.parse(header, why) || !fields.get_string("compression", compression_name) ||
      !fields.get_u32("size", size)) {
    ++counters_.chunks_bad;
    issue(offset, fmt("Chunk record at offset %llu: %s; chunk skipped", ull(offset),
                      why.empty() ? "no compression or size field" : why.c_str()));
    return false;
  }
  if (summary != nullptr) {
    summary->offset = offset;
    summary->compression = compression_name;
    summary->compressed_bytes = data.size();
    summary->uncompressed_bytes = size;
  }
  const ChunkCompression compression = parse_chunk_compression(compression_name);
  if (compression == ChunkCompression::kUnknown) {
    ++counters_.chunks_bad;
    issue(offset,
          fmt("Chunk record at offset %llu: unknown compression '%s' (known: none, bz2, "
              "lz4); chunk skipped",
              ull(offset), printable_prefix(fields.find("compression").value(), 32).c_str()));
    return false;
  }
  if (size > options_.max_chunk_bytes) {
    ++counters_.chunks_bad;
    issue(offset, fmt("Chunk record at offset %llu claims %llu B uncompressed, more than the "
                      "%llu B allowed; chunk skipped",
                      ull(offset), ull(size), ull(options_.max_chunk_bytes)));
    return false;
  }
  if (compression == ChunkCompression::kNone) {
    // Uncompressed records are read in place, without a copy.
    records = data;
    if (data.size() != size) {
      issue(offset, fmt("Chunk record at offset %llu: uncompressed chunk of %zu B, its header says "
                        "%u B; reading the %zu B present",
                        ull(offset), data.size(), size, data.size()));
    }
  } else {
    if (!decompressor_.decompress(compression, data, size, buffer, why)) {
      ++counters_.chunks_bad;
      issue(offset,
            fmt("Chunk record at offset %llu: %s; chunk skipped", ull(offset), why.c_str()));
      return false;
    }
    records = buffer;
  }
  ++counters_.chunks;
  return true;
}

bool BagReader::message_at(std::span<const std::byte> records, std::uint64_t offset_in_chunk,
                           std::uint64_t chunk_offset, std::uint32_t expected_conn,
                           BagMessage& out) {
  BagRecord record;
  std::uint64_t needed = 0;
  if (read_record(records, offset_in_chunk, record, needed) != RecordStatus::kOk) {
    ++counters_.bad_index_entries;
    issue(chunk_offset, fmt("chunk at offset %llu: message record at +%llu runs past the chunk's "
                            "end (needs %llu B)",
                            ull(chunk_offset), ull(offset_in_chunk), ull(needed)));
    return false;
  }
  RecordFields fields;
  std::string why;
  std::uint8_t op = 0;
  std::uint32_t conn = 0;
  std::uint64_t time_ns = 0;
  if (!fields.parse(record.header, why) || !fields.get_u8("op", op) ||
      op != static_cast<std::uint8_t>(BagOp::kMessageData) || !fields.get_u32("conn", conn) ||
      !fields.get_time_ns("time", time_ns)) {
    ++counters_.bad_records;
    issue(chunk_offset,
          fmt("chunk at offset %llu: record at +%llu is not a valid MessageData "
              "record%s%s",
              ull(chunk_offset), ull(offset_in_chunk), why.empty() ? "" : ": ", why.c_str()));
    return false;
  }
  if (expected_conn != kAnyConnection && conn != expected_conn) {
    ++counters_.bad_index_entries;
    issue(chunk_offset, fmt("chunk at offset %llu: the index puts connection %u at +%llu, the "
                            "record there is on connection %u",
                            ull(chunk_offset), expected_conn, ull(offset_in_chunk), conn));
    return false;
  }
  const auto it = connections_.find(conn);
  if (it == connections_.end()) {
    ++counters_.orphan_messages;
    issue(chunk_offset, fmt("chunk at offset %llu: message at +%llu on connection %u, which no "
                            "Connection record defines; skipped",
                            ull(chunk_offset), ull(offset_in_chunk), conn));
    return false;
  }
  out.connection = &it->second;
  out.receive_time_ns = time_ns;
  out.data = record.data;
  out.chunk_offset = chunk_offset;
  out.offset_in_chunk = offset_in_chunk;
  ++counters_.messages;
  return true;
}

const BagReader::CachedChunk* BagReader::chunk_records(std::uint32_t chunk) {
  ++use_clock_;
  for (CachedChunk& c : cache_) {
    if (c.chunk == chunk && c.ok) {
      c.last_use = use_clock_;
      return &c;
    }
  }
  CachedChunk* slot = nullptr;
  if (cache_.size() < std::max<std::size_t>(1, options_.chunk_cache)) {
    slot = &cache_.emplace_back();
  } else {
    slot = &*std::min_element(
        cache_.begin(), cache_.end(),
        [](const CachedChunk& a, const CachedChunk& b) { return a.last_use < b.last_use; });
  }
  slot->chunk = chunk;
  slot->last_use = use_clock_;
  slot->ok = false;
  const std::uint64_t offset = chunks_[chunk].offset;
  BagRecord record;
  std::uint64_t needed = 0;
  // The index check already read this record, so it is whole.
  read_record(file_, offset, record, needed);
  if (!decompress(offset, record.header, record.data, slot->buffer, slot->records, nullptr)) {
    chunk_failed_[chunk] = true;
    return nullptr;
  }
  slot->ok = true;
  report_progress(offset + record.size_bytes);
  return slot;
}

bool BagReader::next_indexed(BagMessage& out) {
  while (next_entry_ < entries_.size()) {
    const IndexEntry e = entries_[next_entry_++];
    if (chunk_failed_[e.chunk]) continue;
    const CachedChunk* c = chunk_records(e.chunk);
    if (c == nullptr) continue;
    if (message_at(c->records, e.offset, chunks_[e.chunk].offset, e.conn, out)) return true;
  }
  done_ = true;
  report_progress(file_.size());
  return false;
}

bool BagReader::enter_chunk(std::span<const std::byte> header, std::uint64_t offset,
                            std::span<const std::byte> data) {
  scan_entries_.clear();
  next_scan_entry_ = 0;
  chunk_offset_ = offset;
  BagChunkSummary summary;
  const bool ok = decompress(offset, header, data, chunk_buffer_, chunk_records_, &summary);
  if (!ok) {
    chunk_records_ = {};
    chunks_.push_back(summary);
    return false;
  }
  std::uint64_t p = 0;
  bool have_time = false;
  while (p < chunk_records_.size()) {
    BagRecord record;
    std::uint64_t needed = 0;
    if (read_record(chunk_records_, p, record, needed) != RecordStatus::kOk) {
      issue(offset, fmt("chunk at offset %llu: record at +%llu is cut short (needs %llu B, %llu B "
                        "left); the rest of the chunk skipped",
                        ull(offset), ull(p), ull(needed), ull(chunk_records_.size() - p)));
      break;
    }
    RecordFields fields;
    std::string why;
    std::uint8_t op = 0;
    if (!fields.parse(record.header, why) || !fields.get_u8("op", op)) {
      ++counters_.bad_records;
      issue(offset, fmt("chunk at offset %llu: record at +%llu: %s; skipped", ull(offset), ull(p),
                        why.empty() ? "no op field" : why.c_str()));
    } else if (op == static_cast<std::uint8_t>(BagOp::kConnection)) {
      add_connection(record.header, record.data, offset);
    } else if (op == static_cast<std::uint8_t>(BagOp::kMessageData)) {
      std::uint64_t time_ns = 0;
      fields.get_time_ns("time", time_ns);  // a record without one is reported on delivery
      scan_entries_.push_back({time_ns, p});
      summary.start_time_ns = have_time ? std::min(summary.start_time_ns, time_ns) : time_ns;
      summary.end_time_ns = std::max(summary.end_time_ns, time_ns);
      have_time = true;
      ++summary.message_count;
    } else {
      ++counters_.unknown_records;
      issue(offset, fmt("chunk at offset %llu: %s record (op 0x%02x) at +%llu does not belong in a "
                        "chunk; skipped",
                        ull(offset), std::string(op_name(op)).c_str(), op, ull(p)));
    }
    p += record.size_bytes;
  }
  std::stable_sort(scan_entries_.begin(), scan_entries_.end(),
                   [](const ScanEntry& a, const ScanEntry& b) { return a.time_ns < b.time_ns; });
  chunks_.push_back(summary);
  return true;
}

bool BagReader::next_sequential(BagMessage& out) {
  for (;;) {
    while (next_scan_entry_ < scan_entries_.size()) {
      const ScanEntry e = scan_entries_[next_scan_entry_++];
      if (message_at(chunk_records_, e.offset, chunk_offset_, kAnyConnection, out)) return true;
    }
    if (pos_ >= file_.size()) {
      if (index_unusable_) {
        // The records end cleanly, but the index the header promises is missing or partial.
        stop(file_.size(),
             fmt("the bag ends at offset %llu after complete records, %s its index at offset "
                 "%llu: cut short",
                 ull(file_.size()), index_pos_ >= file_.size() ? "before" : "inside",
                 ull(index_pos_)));
      }
      done_ = true;
      report_progress(file_.size());
      return false;
    }
    BagRecord record;
    std::uint64_t needed = 0;
    if (read_record(file_, pos_, record, needed) != RecordStatus::kOk) {
      const std::uint64_t left = file_.size() - pos_;
      const std::span<const std::byte> partial_header =
          left >= 4 ? file_.subspan(static_cast<std::size_t>(pos_ + 4),
                                    static_cast<std::size_t>(std::min<std::uint64_t>(
                                        left - 4, load_u32(file_.data() + pos_))))
                    : std::span<const std::byte>{};
      stop(pos_, fmt("truncated %srecord at offset %llu: needs %llu B, %llu B left; the bag ends "
                     "there (cut short?)",
                     op_of(partial_header).c_str(), ull(pos_), ull(needed), ull(left)));
      done_ = true;
      report_progress(file_.size());
      return false;
    }
    const std::uint64_t at = pos_;
    pos_ += record.size_bytes;
    RecordFields fields;
    std::string why;
    std::uint8_t op = 0;
    if (!fields.parse(record.header, why) || !fields.get_u8("op", op)) {
      ++counters_.bad_records;
      issue(at, fmt("record at offset %llu: %s; skipped", ull(at),
                    why.empty() ? "no op field" : why.c_str()));
      continue;
    }
    switch (static_cast<BagOp>(op)) {
      case BagOp::kChunk:
        enter_chunk(record.header, at, record.data);
        report_progress(pos_);
        break;
      case BagOp::kConnection:
        add_connection(record.header, record.data, at);
        break;
      case BagOp::kMessageData:
        // Outside any chunk (not what rosbag writes, but valid records): delivered in place.
        if (message_at(file_, at, at, kAnyConnection, out)) return true;
        break;
      case BagOp::kBagHeader:
      case BagOp::kIndexData:
      case BagOp::kChunkInfo:
        break;  // the index: not needed for a scan
      default:
        ++counters_.unknown_records;
        issue(at, fmt("unknown op 0x%02x record at offset %llu (%llu B) skipped", op, ull(at),
                      ull(record.size_bytes)));
        break;
    }
  }
}

bool BagReader::next(BagMessage& out) {
  if (done_) return false;
  return indexed_ ? next_indexed(out) : next_sequential(out);
}

}  // namespace posed::drivers::recording::ros1
