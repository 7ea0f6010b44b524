#include "drivers/recording/mcap_writer.hpp"

#include <fcntl.h>
#include <lz4frame.h>
#include <unistd.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>

#include "drivers/recording/mcap_format.hpp"

namespace posed::drivers::recording {

using mcap::Op;
using mcap::Out;

std::string_view to_string(McapCompression c) {
  switch (c) {
    case McapCompression::kNone:
      return "";
    case McapCompression::kLz4:
      return "lz4";
    case McapCompression::kZstd:
      return "zstd";
  }
  return "";
}

bool parse_compression(std::string_view text, McapCompression& out) {
  if (text.empty() || text == "none") {
    out = McapCompression::kNone;
  } else if (text == "lz4") {
    out = McapCompression::kLz4;
  } else if (text == "zstd") {
    out = McapCompression::kZstd;
  } else {
    return false;
  }
  return true;
}

McapWriter::~McapWriter() {
  close();
  if (zstd_ctx_ != nullptr) ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_ctx_));
}

bool McapWriter::fail(const char* what, int err) {
  if (error_.empty()) error_ = "mcap " + path_ + ": " + what + ": " + std::strerror(err);
  return false;
}

bool McapWriter::open(const std::string& path, const McapWriterOptions& options,
                      std::string& error) {
  close();
  options_ = options;
  if (options_.chunk_size_bytes == 0) options_.chunk_size_bytes = 1;
  path_ = path;
  error_.clear();
  file_offset_ = 0;
  data_crc_.reset();
  schemas_.clear();
  channels_.clear();
  touched_channels_.clear();
  chunk_.clear();
  chunk_.reserve(options_.chunk_size_bytes + 64 * 1024);
  chunk_start_ns_ = chunk_end_ns_ = chunk_messages_ = 0;
  message_count_ = 0;
  start_ns_ = end_ns_ = 0;
  chunks_since_sync_ = 0;
  chunk_infos_.clear();
  metadata_index_.clear();

  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    error = "mcap " + path + ": cannot create: " + std::strerror(errno);
    return false;
  }
  out_.clear();
  Out o(out_);
  o.put(mcap::kMagic.data(), mcap::kMagicSize);
  const auto at = o.begin_record(Op::kHeader);
  o.str(options_.profile);
  o.str(options_.library);
  o.finish_record(at);
  if (!write_out(out_, true)) {
    error = error_;
    ::close(fd_);
    fd_ = -1;
    return false;
  }
  return true;
}

void McapWriter::write_schema_record(std::vector<std::byte>& buf, const SchemaRec& s) const {
  Out o(buf);
  const auto at = o.begin_record(Op::kSchema);
  o.u16(s.id);
  o.str(s.name);
  o.str(s.encoding);
  o.u32(static_cast<std::uint32_t>(s.data.size()));
  o.bytes(s.data);
  o.finish_record(at);
}

void McapWriter::write_channel_record(std::vector<std::byte>& buf, const ChannelRec& c) const {
  Out o(buf);
  const auto at = o.begin_record(Op::kChannel);
  o.u16(c.id);
  o.u16(c.schema_id);
  o.str(c.topic);
  o.str(c.encoding);
  const auto map_at = o.begin_u32_length();
  for (const auto& [k, v] : c.metadata) {
    o.str(k);
    o.str(v);
  }
  o.finish_u32_length(map_at);
  o.finish_record(at);
}

std::uint16_t McapWriter::add_schema(std::string_view name, std::string_view encoding,
                                     std::span<const std::byte> data) {
  if (fd_ < 0 || schemas_.size() >= 0xFFFE) return 0;
  SchemaRec s;
  s.id = static_cast<std::uint16_t>(schemas_.size() + 1);  // 0 means "no schema" (spec)
  s.name = name;
  s.encoding = encoding;
  s.data.assign(data.begin(), data.end());
  schemas_.push_back(std::move(s));
  return schemas_.back().id;
}

std::uint16_t McapWriter::add_channel(std::string_view topic, std::string_view message_encoding,
                                      std::uint16_t schema_id,
                                      const std::map<std::string, std::string>& metadata) {
  if (fd_ < 0 || channels_.size() >= 0xFFFF) return 0xFFFF;
  ChannelRec c;
  c.id = static_cast<std::uint16_t>(channels_.size());
  c.schema_id = schema_id <= schemas_.size() ? schema_id : 0;
  c.topic = topic;
  c.encoding = message_encoding;
  c.metadata = metadata;
  channels_.push_back(std::move(c));
  return channels_.back().id;
}

bool McapWriter::write_message(std::uint16_t channel_id, std::uint32_t sequence,
                               std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
                               std::span<const std::byte> data) {
  if (fd_ < 0 || channel_id >= channels_.size()) return false;
  ChannelRec& ch = channels_[channel_id];
  if (!ch.in_chunk_file) {
    // First use: the Schema and Channel records go into this chunk, before the message, so
    // every prefix of the file that holds the message also describes it (crash safety).
    if (ch.schema_id != 0 && !schemas_[ch.schema_id - 1u].in_chunk_file) {
      write_schema_record(chunk_, schemas_[ch.schema_id - 1u]);
      schemas_[ch.schema_id - 1u].in_chunk_file = true;
    }
    write_channel_record(chunk_, ch);
    ch.in_chunk_file = true;
  }
  if (ch.index.empty()) touched_channels_.push_back(channel_id);
  ch.index.emplace_back(log_time_ns, chunk_.size());
  Out o(chunk_);
  o.u8(static_cast<std::uint8_t>(Op::kMessage));
  o.u64(2 + 4 + 8 + 8 + data.size());
  o.u16(channel_id);
  o.u32(sequence);
  o.u64(log_time_ns);
  o.u64(publish_time_ns);
  o.bytes(data);
  if (chunk_messages_ == 0 || log_time_ns < chunk_start_ns_) chunk_start_ns_ = log_time_ns;
  if (chunk_messages_ == 0 || log_time_ns > chunk_end_ns_) chunk_end_ns_ = log_time_ns;
  if (message_count_ == 0 || log_time_ns < start_ns_) start_ns_ = log_time_ns;
  if (message_count_ == 0 || log_time_ns > end_ns_) end_ns_ = log_time_ns;
  ++chunk_messages_;
  ++message_count_;
  ++ch.message_count;
  if (chunk_.size() >= options_.chunk_size_bytes) return flush_chunk();
  return error_.empty();
}

bool McapWriter::compress_chunk(std::span<const std::byte> in, std::string_view& compression) {
  compression = to_string(options_.compression);
  switch (options_.compression) {
    case McapCompression::kNone:
      return true;
    case McapCompression::kLz4: {
      // The LZ4 *frame* format (spec, "Supported compression formats"), default fast level.
      LZ4F_preferences_t prefs{};
      prefs.frameInfo.contentSize = in.size();
      const std::size_t bound = LZ4F_compressFrameBound(in.size(), &prefs);
      if (compressed_.size() < bound) compressed_.resize(bound);
      const std::size_t n =
          LZ4F_compressFrame(compressed_.data(), compressed_.size(), in.data(), in.size(), &prefs);
      if (LZ4F_isError(n) != 0u) return false;
      compressed_.resize(n);
      return true;
    }
    case McapCompression::kZstd: {
      if (zstd_ctx_ == nullptr) zstd_ctx_ = ZSTD_createCCtx();
      const std::size_t bound = ZSTD_compressBound(in.size());
      if (compressed_.size() < bound) compressed_.resize(bound);
      const std::size_t n =
          ZSTD_compressCCtx(static_cast<ZSTD_CCtx*>(zstd_ctx_), compressed_.data(),
                            compressed_.size(), in.data(), in.size(), options_.zstd_level);
      if (ZSTD_isError(n) != 0u) return false;
      compressed_.resize(n);
      return true;
    }
  }
  return false;
}

bool McapWriter::flush_chunk() {
  if (fd_ < 0) return false;
  if (chunk_.empty()) return error_.empty();
  const std::uint32_t crc = crc32(chunk_);
  std::string_view compression;
  std::span<const std::byte> records = chunk_;
  if (options_.compression != McapCompression::kNone) {
    compressed_.resize(0);
    if (compress_chunk(chunk_, compression) && compressed_.size() < chunk_.size()) {
      records = compressed_;
    } else {
      compression = "";  // incompressible (or a codec error): store; the spec allows per chunk
    }
  }
  McapChunkInfo info;
  info.start_offset = file_offset_;
  info.message_count = chunk_messages_;
  info.message_start_time_ns = chunk_messages_ > 0 ? chunk_start_ns_ : 0;
  info.message_end_time_ns = chunk_messages_ > 0 ? chunk_end_ns_ : 0;
  info.compressed_size_bytes = records.size();
  info.uncompressed_size_bytes = chunk_.size();
  info.compression = compression;

  out_.clear();
  Out o(out_);
  o.u8(static_cast<std::uint8_t>(Op::kChunk));
  const std::uint64_t content = 8 + 8 + 8 + 4 + 4 + compression.size() + 8 + records.size();
  o.u64(content);
  o.u64(info.message_start_time_ns);
  o.u64(info.message_end_time_ns);
  o.u64(chunk_.size());
  o.u32(crc);
  o.str(compression);
  o.u64(records.size());
  // The records themselves are written straight from their buffer: no copy of the chunk.
  const std::size_t header_size = out_.size();
  info.chunk_length = header_size + records.size();

  std::vector<std::byte> index_buf;
  Out ix(index_buf);
  const std::uint64_t index_base = info.start_offset + info.chunk_length;
  for (std::uint16_t id : touched_channels_) {
    ChannelRec& ch = channels_[id];
    info.message_index_offsets[id] = index_base + index_buf.size();
    const auto at = ix.begin_record(Op::kMessageIndex);
    ix.u16(id);
    const auto arr = ix.begin_u32_length();
    for (const auto& [t, off] : ch.index) {
      ix.u64(t);
      ix.u64(off);
    }
    ix.finish_u32_length(arr);
    ix.finish_record(at);
    ch.index.clear();
  }
  touched_channels_.clear();
  info.index_end_offset = index_base + index_buf.size();

  const bool ok = write_out(out_, true) && write_out(records, true) && write_out(index_buf, true);
  chunk_.clear();
  chunk_messages_ = 0;
  chunk_infos_.push_back(std::move(info));
  if (!ok) return false;
  if (options_.fsync_every_chunks > 0 && ++chunks_since_sync_ >= options_.fsync_every_chunks) {
    chunks_since_sync_ = 0;
    if (::fdatasync(fd_) != 0) return fail("fdatasync", errno);
  }
  return true;
}

bool McapWriter::write_metadata(std::string_view name,
                                const std::map<std::string, std::string>& entries) {
  if (fd_ < 0) return false;
  // Metadata records may not sit inside chunks; close the open one so file order = time order.
  if (!flush_chunk()) return false;
  out_.clear();
  Out o(out_);
  const auto at = o.begin_record(Op::kMetadata);
  o.str(name);
  const auto map_at = o.begin_u32_length();
  for (const auto& [k, v] : entries) {
    o.str(k);
    o.str(v);
  }
  o.finish_u32_length(map_at);
  o.finish_record(at);
  metadata_index_.push_back({file_offset_, out_.size(), std::string(name)});
  return write_out(out_, true);
}

bool McapWriter::write_out(std::span<const std::byte> bytes, bool data_section) {
  if (!error_.empty()) return false;
  if (data_section) data_crc_.update(bytes);
  const std::byte* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail("write", errno);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  file_offset_ += bytes.size();
  return true;
}

bool McapWriter::close() {
  if (fd_ < 0) return error_.empty();
  flush_chunk();

  // DataEnd: CRC of every byte before it, from the leading magic on (what the reference
  // writers compute for "all bytes in the data section").
  out_.clear();
  Out o(out_);
  {
    const auto at = o.begin_record(Op::kDataEnd);
    o.u32(data_crc_.value());
    o.finish_record(at);
  }
  write_out(out_, false);

  // Summary: records grouped by opcode (spec, "Summary Section"); Channels before Statistics.
  const std::uint64_t summary_start = file_offset_;
  out_.clear();
  struct Group {
    Op op;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  auto group = [&](Op op, auto&& body) {
    const std::size_t before = out_.size();
    body();
    if (out_.size() > before) {
      groups.push_back({op, summary_start + before, out_.size() - before});
    }
  };
  group(Op::kSchema, [&] {
    for (const auto& s : schemas_) write_schema_record(out_, s);
  });
  group(Op::kChannel, [&] {
    for (const auto& c : channels_) write_channel_record(out_, c);
  });
  group(Op::kStatistics, [&] {
    const auto at = o.begin_record(Op::kStatistics);
    o.u64(message_count_);
    o.u16(static_cast<std::uint16_t>(schemas_.size()));
    o.u32(static_cast<std::uint32_t>(channels_.size()));
    o.u32(0);  // attachments
    o.u32(static_cast<std::uint32_t>(metadata_index_.size()));
    o.u32(static_cast<std::uint32_t>(chunk_infos_.size()));
    o.u64(message_count_ > 0 ? start_ns_ : 0);
    o.u64(message_count_ > 0 ? end_ns_ : 0);
    const auto map_at = o.begin_u32_length();
    for (const auto& c : channels_) {
      o.u16(c.id);
      o.u64(c.message_count);
    }
    o.finish_u32_length(map_at);
    o.finish_record(at);
  });
  group(Op::kChunkIndex, [&] {
    for (const auto& c : chunk_infos_) {
      const auto at = o.begin_record(Op::kChunkIndex);
      o.u64(c.message_start_time_ns);
      o.u64(c.message_end_time_ns);
      o.u64(c.start_offset);
      o.u64(c.chunk_length);
      const auto map_at = o.begin_u32_length();
      for (const auto& [id, off] : c.message_index_offsets) {
        o.u16(id);
        o.u64(off);
      }
      o.finish_u32_length(map_at);
      o.u64(c.index_end_offset - c.start_offset - c.chunk_length);
      o.str(c.compression);
      o.u64(c.compressed_size_bytes);
      o.u64(c.uncompressed_size_bytes);
      o.finish_record(at);
    }
  });
  group(Op::kMetadataIndex, [&] {
    for (const auto& m : metadata_index_) {
      const auto at = o.begin_record(Op::kMetadataIndex);
      o.u64(m.offset);
      o.u64(m.length);
      o.str(m.name);
      o.finish_record(at);
    }
  });
  const std::uint64_t summary_offset_start = summary_start + out_.size();
  for (const auto& g : groups) {
    const auto at = o.begin_record(Op::kSummaryOffset);
    o.u8(static_cast<std::uint8_t>(g.op));
    o.u64(g.start);
    o.u64(g.length);
    o.finish_record(at);
  }
  // Footer: the summary CRC covers the summary, the summary offsets and the Footer up to and
  // including summary_offset_start (spec, "Footer").
  o.u8(static_cast<std::uint8_t>(Op::kFooter));
  o.u64(mcap::kFooterContentSize);
  o.u64(summary_start);
  o.u64(summary_offset_start);
  o.u32(crc32(out_));
  o.put(mcap::kMagic.data(), mcap::kMagicSize);
  write_out(out_, false);

  if (options_.fsync_on_close && error_.empty() && ::fsync(fd_) != 0) fail("fsync", errno);
  if (::close(fd_) != 0) fail("close", errno);
  fd_ = -1;
  return error_.empty();
}

}  // namespace posed::drivers::recording
