#include "drivers/recording/mcap_reader.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "drivers/recording/mcap_format.hpp"

namespace posed::drivers::recording {

using mcap::In;
using mcap::Op;

const char* mcap::op_name(std::uint8_t opcode) {
  switch (static_cast<Op>(opcode)) {
    case Op::kHeader:
      return "Header";
    case Op::kFooter:
      return "Footer";
    case Op::kSchema:
      return "Schema";
    case Op::kChannel:
      return "Channel";
    case Op::kMessage:
      return "Message";
    case Op::kChunk:
      return "Chunk";
    case Op::kMessageIndex:
      return "MessageIndex";
    case Op::kChunkIndex:
      return "ChunkIndex";
    case Op::kAttachment:
      return "Attachment";
    case Op::kAttachmentIndex:
      return "AttachmentIndex";
    case Op::kStatistics:
      return "Statistics";
    case Op::kMetadata:
      return "Metadata";
    case Op::kMetadataIndex:
      return "MetadataIndex";
    case Op::kSummaryOffset:
      return "SummaryOffset";
    case Op::kDataEnd:
      return "DataEnd";
  }
  return "unknown";
}

namespace {

/// How much read file next() lets accumulate before it releases it from memory (one madvise, a
/// few microseconds), and the step in which the data CRC is folded. A replay runs a reader per
/// stream over the same mapping, so what each holds adds up: at 32 MB the mapped pages swung
/// posed's resident memory by 60 MB over a 10-minute replay at recorded timing, at 4 MB (and the
/// CRC in 8 MB steps) still by 20 MB from one sample to the next (docs/faults.md, stop 46). A
/// reader now holds its current record and at most this much behind it.
constexpr std::uint64_t kReleaseStepBytes = 256u << 10;
/// How far behind what it released last a release starts again. A page fault maps the pages around
/// the faulting one that the page cache holds (fault-around: 64 kB by default, a whole large folio
/// on newer kernels), some of them behind what was released: a reader that skips the chunks
/// another decompressed touches little more than record headers, and so kept 3.4 % of the file.
constexpr std::uint64_t kFaultAroundSlackBytes = 2u << 20;

std::string fmt(const char* f, auto... args) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, args...);
  return buf;
}

unsigned long long ull(std::uint64_t v) { return static_cast<unsigned long long>(v); }

bool read_string_map(In& in, std::map<std::string, std::string>& out) {
  const std::uint32_t len = in.u32();
  In m(in.take(len));
  while (in.ok() && m.ok() && m.remaining() > 0) {
    std::string k = m.str();
    std::string v = m.str();
    if (m.ok()) out[std::move(k)] = std::move(v);
  }
  return in.ok() && m.ok();
}

}  // namespace

McapReader::McapReader() = default;

McapReader::~McapReader() {
  if (zstd_ctx_ != nullptr) ZSTD_freeDCtx(static_cast<ZSTD_DCtx*>(zstd_ctx_));
  if (lz4_ctx_ != nullptr) LZ4F_freeDecompressionContext(static_cast<LZ4F_dctx*>(lz4_ctx_));
}

bool McapReader::open(const std::string& path, std::string& error, McapReaderOptions options) {
  path_ = path;
  options_ = options;
  if (!mapped_.open(path, error, "mcap")) return false;
  file_ = mapped_.bytes();
  return open_common(error);
}

bool McapReader::open_bytes(std::span<const std::byte> bytes, std::string& error,
                            McapReaderOptions options) {
  path_ = "<memory>";
  options_ = options;
  mapped_.close();
  file_ = bytes;
  return open_common(error);
}

void McapReader::issue(std::uint64_t offset, std::string what) {
  ++counters_.issues;
  if (issues_.size() < 100) issues_.push_back({offset, std::move(what)});
}

void McapReader::unknown(std::uint64_t offset, std::int64_t chunk_byte, std::uint8_t opcode,
                         std::uint64_t length) {
  ++counters_.unknown_records;
  if (unknown_records_.size() < 100)
    unknown_records_.push_back({offset, chunk_byte, opcode, length});
}

void McapReader::stop(std::uint64_t offset, std::string what) {
  stop_reason_ = fmt("%s at offset %llu; read up to offset %llu of %llu B", what.c_str(),
                     ull(offset), ull(offset), ull(file_.size()));
  issue(offset, std::move(what));
  pos_ = offset;
  done_ = true;
}

bool McapReader::open_common(std::string& error) {
  channels_.clear();
  schemas_.clear();
  metadata_.clear();
  issues_.clear();
  unknown_records_.clear();
  summary_ = {};
  counters_ = {};
  data_crc_decided_ = false;
  if (file_.size() < mcap::kMagicSize ||
      std::memcmp(file_.data(), mcap::kMagic.data(), mcap::kMagicSize) != 0) {
    error = "mcap " + path_ + ": not an MCAP file (bad or missing magic at offset 0)";
    return false;
  }
  In in(file_.subspan(mcap::kMagicSize));
  const std::uint8_t op = in.u8();
  const std::uint64_t len = in.u64();
  if (!in.ok() || op != static_cast<std::uint8_t>(Op::kHeader)) {
    error = fmt("mcap %s: expected a Header record at offset 8, found %s", path_.c_str(),
                in.ok() ? mcap::op_name(op) : "the end of the file");
    return false;
  }
  In h(in.take(len));
  profile_ = h.str();
  library_ = h.str();
  if (!in.ok() || !h.ok()) {
    error = "mcap " + path_ + ": Header record at offset 8 is truncated or malformed";
    return false;
  }
  data_start_ = mcap::kMagicSize + in.pos();
  summary_channels_.reset();
  read_summary();
  for (const auto& [id, c] : channels_) summary_channels_.set(id);
  rewind();
  return true;
}

void McapReader::read_summary() {
  const std::size_t tail = mcap::kRecordPrefixSize + mcap::kFooterContentSize + mcap::kMagicSize;
  if (file_.size() < data_start_ + tail ||
      std::memcmp(file_.data() + file_.size() - mcap::kMagicSize, mcap::kMagic.data(),
                  mcap::kMagicSize) != 0) {
    issue(file_.size(), "no Footer and trailing magic (file cut short?): reading by linear scan");
    return;
  }
  const std::uint64_t footer_at = file_.size() - tail;
  In f(file_.subspan(static_cast<std::size_t>(footer_at)));
  const std::uint8_t op = f.u8();
  const std::uint64_t len = f.u64();
  const std::uint64_t summary_start = f.u64();
  const std::uint64_t summary_offset_start = f.u64();
  const std::uint32_t summary_crc = f.u32();
  if (op != static_cast<std::uint8_t>(Op::kFooter) || len != mcap::kFooterContentSize) {
    issue(footer_at, "trailing magic without a Footer record: reading by linear scan");
    return;
  }
  summary_.footer_found = true;
  if (summary_start == 0) return;  // a valid file without a summary
  summary_.present = true;
  if (summary_start < data_start_ || summary_start > footer_at ||
      (summary_offset_start != 0 &&
       (summary_offset_start < summary_start || summary_offset_start > footer_at))) {
    issue(footer_at, fmt("Footer points outside the file (summary_start %llu): linear scan",
                         ull(summary_start)));
    return;
  }
  if (summary_crc != 0 && options_.verify_crcs) {
    // covers the summary, the summary offsets and the Footer through summary_offset_start
    const auto covered =
        file_.subspan(static_cast<std::size_t>(summary_start),
                      static_cast<std::size_t>(footer_at - summary_start + 1 + 8 + 16));
    const std::uint32_t crc = crc32(covered);
    if (crc != summary_crc) {
      issue(summary_start, fmt("summary CRC mismatch (stored 0x%08x, computed 0x%08x): ignoring "
                               "the summary, reading by linear scan",
                               summary_crc, crc));
      return;
    }
  }
  summary_.crc_ok = true;
  const std::uint64_t end = summary_offset_start != 0 ? summary_offset_start : footer_at;
  std::uint64_t p = summary_start;
  std::map<std::uint16_t, McapChannelRecord> saved_channels;
  bool ok = true;
  while (p < end) {
    In r(file_.subspan(static_cast<std::size_t>(p), static_cast<std::size_t>(end - p)));
    const std::uint8_t rop = r.u8();
    const std::uint64_t rlen = r.u64();
    auto body = r.take(rlen);
    if (!r.ok()) {
      issue(p, "truncated record in the summary: ignoring the summary");
      ok = false;
      break;
    }
    In b(body);
    switch (static_cast<Op>(rop)) {
      case Op::kSchema:
        ok = parse_schema(body, p) && ok;
        break;
      case Op::kChannel:
        ok = parse_channel(body, p) && ok;
        break;
      case Op::kStatistics: {
        summary_.message_count = b.u64();
        b.u16();
        b.u32();
        b.u32();
        b.u32();
        summary_.chunk_count = b.u32();
        summary_.message_start_time_ns = b.u64();
        summary_.message_end_time_ns = b.u64();
        In m(b.take(b.u32()));
        while (b.ok() && m.ok() && m.remaining() > 0) {
          const std::uint16_t id = m.u16();
          const std::uint64_t n = m.u64();
          if (m.ok()) summary_.channel_message_counts[id] = n;
        }
        summary_.has_statistics = b.ok() && m.ok();
        if (!summary_.has_statistics) {
          issue(p, "malformed Statistics record in the summary");
          ok = false;
        }
        break;
      }
      case Op::kChunkIndex:
        ++summary_.chunk_index_count;
        break;
      default:
        break;  // other summary records are not needed by a linear reader
    }
    p += mcap::kRecordPrefixSize + rlen;
  }
  summary_.parsed = ok;
  if (!ok) {
    channels_.clear();
    schemas_.clear();
  }
}

const McapSchemaRecord* McapReader::schema(std::uint16_t id) const {
  const auto it = schemas_.find(id);
  return it == schemas_.end() ? nullptr : &it->second;
}

bool McapReader::parse_schema(std::span<const std::byte> body, std::uint64_t offset) {
  In in(body);
  McapSchemaRecord s;
  s.id = in.u16();
  s.name = in.str();
  s.encoding = in.str();
  auto data = in.take(in.u32());
  if (!in.ok()) {
    ++counters_.bad_records;
    issue(offset, "malformed Schema record");
    return false;
  }
  if (s.id == 0) return true;  // invalid id: ignored, as the spec says
  s.data.assign(data.begin(), data.end());
  schemas_[s.id] = std::move(s);
  return true;
}

bool McapReader::parse_channel(std::span<const std::byte> body, std::uint64_t offset) {
  In in(body);
  McapChannelRecord c;
  c.id = in.u16();
  c.schema_id = in.u16();
  c.topic = in.str();
  c.message_encoding = in.str();
  if (!read_string_map(in, c.metadata) || !in.ok()) {
    ++counters_.bad_records;
    issue(offset, "malformed Channel record");
    return false;
  }
  if (c.schema_id != 0 && schemas_.find(c.schema_id) == schemas_.end()) {
    issue(offset, fmt("Channel %u (%s) refers to schema %u, which is not defined before it", c.id,
                      c.topic.c_str(), c.schema_id));
  }
  seen_channels_.set(c.id);
  if (const auto it = channels_.find(c.id); it != channels_.end()) {
    // Repeats (summary copy, next chunk) must be identical (spec); keep the first one so the
    // pointers handed out in McapMessage stay valid.
    return true;
  }
  channels_[c.id] = std::move(c);
  return true;
}

void McapReader::rewind() {
  pos_ = data_start_;
  released_ = 0;
  done_ = false;
  complete_ = false;
  stop_reason_.clear();
  data_crc_.reset();
  crc_pos_ = 0;
  chunk_records_ = {};
  chunk_pos_ = 0;
  shared_chunk_.reset();
  seen_channels_.reset();
}

bool McapReader::decode_message(std::span<const std::byte> body, std::uint64_t offset,
                                McapMessage& out) {
  In in(body);
  const std::uint16_t channel_id = in.u16();
  out.sequence = in.u32();
  out.log_time_ns = in.u64();
  out.publish_time_ns = in.u64();
  if (!in.ok()) {
    ++counters_.bad_records;
    issue(offset, "malformed Message record");
    return false;
  }
  const auto it = channels_.find(channel_id);
  if (it == channels_.end() || !(summary_channels_[channel_id] || seen_channels_[channel_id])) {
    ++counters_.orphan_messages;
    if (counters_.orphan_messages <= 10) {
      issue(offset, fmt("Message on channel %u, which has no Channel record", channel_id));
    }
    return false;
  }
  out.channel = &it->second;
  out.data = body.subspan(in.pos());
  out.record_offset = offset;
  ++counters_.messages;
  return true;
}

bool McapReader::next_in_chunk(McapMessage& out) {
  while (chunk_pos_ < chunk_records_.size()) {
    In r(chunk_records_.subspan(chunk_pos_));
    const std::uint8_t op = r.u8();
    const std::uint64_t len = r.u64();
    auto body = r.take(len);
    if (!r.ok()) {
      ++counters_.bad_records;
      issue(chunk_offset_,
            fmt("record inside the Chunk at chunk byte %llu overruns the chunk", ull(chunk_pos_)));
      chunk_pos_ = chunk_records_.size();
      break;
    }
    const std::size_t record_at = chunk_pos_;
    chunk_pos_ += mcap::kRecordPrefixSize + static_cast<std::size_t>(len);
    switch (static_cast<Op>(op)) {
      case Op::kSchema:
        parse_schema(body, chunk_offset_);
        break;
      case Op::kChannel:
        parse_channel(body, chunk_offset_);
        break;
      case Op::kMessage:
        if (decode_message(body, chunk_offset_, out)) return true;
        break;
      default:
        // Only Schema/Channel/Message belong in chunks; anything else is skipped.
        unknown(chunk_offset_, static_cast<std::int64_t>(record_at), op, len);
        break;
    }
  }
  chunk_records_ = {};
  chunk_pos_ = 0;
  return false;
}

bool McapReader::enter_chunk(std::span<const std::byte> body, std::uint64_t offset) {
  In in(body);
  in.u64();  // message_start_time
  const std::uint64_t end_time = in.u64();
  const std::uint64_t uncompressed_size = in.u64();
  const std::uint32_t crc = in.u32();
  const std::string compression = in.str();
  const std::uint64_t records_len = in.u64();
  auto records = in.take(records_len);
  if (!in.ok()) {
    ++counters_.bad_records;
    ++counters_.chunks_bad;
    issue(offset, "malformed Chunk record (fields overrun the record)");
    return false;
  }
  if (options_.min_log_time_ns > 0 && end_time < options_.min_log_time_ns && summary_.usable()) {
    ++counters_.chunks_skipped_time;
    return false;
  }
  if (uncompressed_size > options_.max_chunk_bytes) {
    ++counters_.chunks_bad;
    issue(offset, fmt("Chunk claims %llu B uncompressed (limit %llu B): skipped",
                      ull(uncompressed_size), ull(options_.max_chunk_bytes)));
    return false;
  }
  std::span<const std::byte> plain;
  shared_chunk_.reset();
  McapChunkCache* const cache = compression.empty() ? nullptr : options_.chunk_cache.get();
  if (cache != nullptr) {
    if (McapChunkCache::Chunk hit = cache->find(offset)) {
      // Decompressed and CRC-checked by the reader that added it.
      shared_chunk_ = std::move(hit);
      ++counters_.chunks;
      chunk_records_ = *shared_chunk_;
      chunk_pos_ = 0;
      chunk_offset_ = offset;
      return true;
    }
  }
  // A chunk for the cache gets a buffer of its own: the other readers may still walk it after
  // this reader has moved on.
  // Only what this reader checked is shared.
  std::shared_ptr<std::vector<std::byte>> own =
      cache != nullptr && (options_.verify_crcs || crc == 0) ? cache->buffer() : nullptr;
  std::vector<std::byte>& buf = own ? *own : chunk_buf_;
  if (compression.empty()) {
    if (records.size() != uncompressed_size) {
      ++counters_.chunks_bad;
      issue(offset, "uncompressed Chunk whose size disagrees with uncompressed_size: skipped");
      return false;
    }
    plain = records;
  } else if (compression == "lz4") {
    if (lz4_ctx_ == nullptr) {
      LZ4F_dctx* ctx = nullptr;
      LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION);
      lz4_ctx_ = ctx;
    }
    auto* ctx = static_cast<LZ4F_dctx*>(lz4_ctx_);
    LZ4F_resetDecompressionContext(ctx);
    buf.resize(static_cast<std::size_t>(uncompressed_size));
    std::size_t dst_size = buf.size();
    std::size_t src_size = records.size();
    const std::size_t r =
        LZ4F_decompress(ctx, buf.data(), &dst_size, records.data(), &src_size, nullptr);
    if (LZ4F_isError(r) != 0u || r != 0 || dst_size != uncompressed_size) {
      ++counters_.chunks_bad;
      issue(offset,
            fmt("lz4 Chunk does not decompress to %llu B (%s): skipped", ull(uncompressed_size),
                LZ4F_isError(r) != 0u ? LZ4F_getErrorName(r) : "size mismatch"));
      return false;
    }
    plain = buf;
  } else if (compression == "zstd") {
    if (zstd_ctx_ == nullptr) zstd_ctx_ = ZSTD_createDCtx();
    buf.resize(static_cast<std::size_t>(uncompressed_size));
    const std::size_t r = ZSTD_decompressDCtx(static_cast<ZSTD_DCtx*>(zstd_ctx_), buf.data(),
                                              buf.size(), records.data(), records.size());
    if (ZSTD_isError(r) != 0u || r != uncompressed_size) {
      ++counters_.chunks_bad;
      issue(offset,
            fmt("zstd Chunk does not decompress to %llu B (%s): skipped", ull(uncompressed_size),
                ZSTD_isError(r) != 0u ? ZSTD_getErrorName(r) : "size mismatch"));
      return false;
    }
    plain = buf;
  } else {
    ++counters_.chunks_bad;
    issue(offset, "Chunk with unknown compression '" + compression.substr(0, 32) + "': skipped");
    return false;
  }
  if (crc != 0 && options_.verify_crcs) {
    const std::uint32_t got = crc32(plain);
    if (got != crc) {
      ++counters_.chunks_bad;
      issue(offset, fmt("Chunk CRC mismatch (stored 0x%08x, computed 0x%08x): skipped", crc, got));
      return false;
    }
  }
  if (own) {
    shared_chunk_ = own;
    cache->add(offset, std::move(own));
  }
  ++counters_.chunks;
  chunk_records_ = plain;
  chunk_pos_ = 0;
  chunk_offset_ = offset;
  return true;
}

bool McapReader::next(McapMessage& out) {
  if (!data_crc_decided_) {
    // Decided by the first reader that reads, not the first that opens: a reader opened only
    // to list the channels must not take the check with it.
    data_crc_decided_ = true;
    verify_data_crc_ = options_.verify_crcs &&
                       (options_.chunk_cache == nullptr || options_.chunk_cache->claim_data_crc());
  }
  for (;;) {
    if (!chunk_records_.empty() && next_in_chunk(out)) return true;
    if (done_) return false;
    const std::uint64_t at = pos_;
    // What lies before this record (and before the data CRC's position) is read: out of
    // resident memory with it, in steps large enough to cost nothing.
    const std::uint64_t done_with = verify_data_crc_ ? std::min(at, crc_pos_) : at;
    if (done_with >= released_ + kReleaseStepBytes) {
      const std::uint64_t again_from =
          released_ > kFaultAroundSlackBytes ? released_ - kFaultAroundSlackBytes : 0;
      released_ = mapped_.release(static_cast<std::size_t>(again_from),
                                  static_cast<std::size_t>(done_with));
    }
    if (at >= file_.size()) {
      stop(at, "the file ends without a DataEnd record (cut short?)");
      return false;
    }
    In r(file_.subspan(static_cast<std::size_t>(at)));
    const std::uint8_t op = r.u8();
    const std::uint64_t len = r.u64();
    if (!r.ok()) {
      stop(at, fmt("truncated record header (%llu B left)", ull(file_.size() - at)));
      return false;
    }
    auto body = r.take(len);
    if (!r.ok()) {
      stop(at, fmt("truncated %s record: needs %llu B, %llu B left", mcap::op_name(op), ull(len),
                   ull(file_.size() - at - mcap::kRecordPrefixSize)));
      return false;
    }
    const std::uint64_t record_end = at + mcap::kRecordPrefixSize + len;
    if (static_cast<Op>(op) == Op::kDataEnd) {
      if (verify_data_crc_) {
        data_crc_.update(file_.subspan(static_cast<std::size_t>(crc_pos_),
                                       static_cast<std::size_t>(at - crc_pos_)));
        crc_pos_ = at;
        In b(body);
        const std::uint32_t stored = b.u32();
        if (b.ok() && stored != 0 && stored != data_crc_.value()) {
          ++counters_.bad_records;
          issue(at, fmt("data section CRC mismatch (stored 0x%08x, computed 0x%08x)", stored,
                        data_crc_.value()));
        }
      }
      pos_ = record_end;
      done_ = true;
      complete_ = counters_.chunks_bad == 0 && counters_.bad_records == 0;
      counters_.bytes_scanned = record_end;
      return false;
    }
    if (verify_data_crc_ && record_end - crc_pos_ > kReleaseStepBytes) {
      // fold the data CRC forward in steps, one pass over the file, and let the pages go
      data_crc_.update(file_.subspan(static_cast<std::size_t>(crc_pos_),
                                     static_cast<std::size_t>(record_end - crc_pos_)));
      crc_pos_ = record_end;
    }
    pos_ = record_end;
    counters_.bytes_scanned = record_end;
    switch (static_cast<Op>(op)) {
      case Op::kHeader:
        issue(at, "second Header record: skipped");
        break;
      case Op::kFooter:
        // A file without DataEnd (allowed by older writers): the data ends here.
        done_ = true;
        complete_ = counters_.chunks_bad == 0 && counters_.bad_records == 0;
        return false;
      case Op::kSchema:
        parse_schema(body, at);
        break;
      case Op::kChannel:
        parse_channel(body, at);
        break;
      case Op::kMessage:
        if (decode_message(body, at, out)) return true;
        break;
      case Op::kChunk:
        enter_chunk(body, at);
        break;
      case Op::kMetadata: {
        In b(body);
        McapMetadataRecord m;
        m.name = b.str();
        if (read_string_map(b, m.entries)) {
          metadata_.push_back(std::move(m));
        } else {
          ++counters_.bad_records;
          issue(at, "malformed Metadata record");
        }
        break;
      }
      case Op::kMessageIndex:
      case Op::kChunkIndex:
      case Op::kAttachment:
      case Op::kAttachmentIndex:
      case Op::kStatistics:
      case Op::kMetadataIndex:
      case Op::kSummaryOffset:
        break;  // index records: a linear reader does not need them
      default:
        unknown(at, -1, op, len);  // unknown opcode: skipped, as the spec says
        break;
    }
  }
}

}  // namespace posed::drivers::recording
