#pragma once
// MCAP file format constants and little-endian (de)serialisation helpers, after the
// specification at mcap.dev/spec (checked against foxglove/mcap docs/specification/README.md):
//
//   <Magic><Header><Data section>[<Summary section>][<Summary Offset section>]<Footer><Magic>
//   record = <opcode u8><content length u64><content>
//   String = u32 byte length + UTF-8; Bytes (in Schema) = u32 length + bytes;
//   Array/Map = u32 byte length + serialised elements; all integers little-endian.
//
// Used by the writer and the reader only; nothing else needs these details.

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace posed::drivers::recording::mcap {

/// 0x89 'M' 'C' 'A' 'P' '0' '\r' '\n': '0' is the major version (spec, "Magic").
inline constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
inline constexpr std::size_t kMagicSize = kMagic.size();
/// opcode + content length prefix of every record [B]
inline constexpr std::size_t kRecordPrefixSize = 9;
/// Footer content: summary_start u64, summary_offset_start u64, summary_crc u32 [B]
inline constexpr std::size_t kFooterContentSize = 20;

/// Record opcodes (spec, "Records"). 0x80-0xFF are application extensions: skipped by readers.
enum class Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

const char* op_name(std::uint8_t opcode);

/// Appends little-endian fields to a byte buffer.
class Out {
 public:
  explicit Out(std::vector<std::byte>& buf) : buf_(buf) {}
  void u8(std::uint8_t v) { buf_.push_back(static_cast<std::byte>(v)); }
  void u16(std::uint16_t v) { put(&v, 2); }
  void u32(std::uint32_t v) { put(&v, 4); }
  void u64(std::uint64_t v) { put(&v, 8); }
  void str(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size()));
    put(s.data(), s.size());
  }
  void bytes(std::span<const std::byte> b) { put(b.data(), b.size()); }
  void put(const void* p, std::size_t n) {
    const auto* b = static_cast<const std::byte*>(p);
    buf_.insert(buf_.end(), b, b + n);  // little-endian host (x86-64, ARM64)
  }
  /// Starts a record; returns the position of its length field for finish_record().
  std::size_t begin_record(Op op) {
    u8(static_cast<std::uint8_t>(op));
    const std::size_t at = buf_.size();
    u64(0);
    return at;
  }
  void finish_record(std::size_t length_at) {
    const std::uint64_t len = buf_.size() - length_at - 8;
    std::memcpy(buf_.data() + length_at, &len, 8);
  }
  /// Starts a u32-length-prefixed Array/Map; finish with finish_u32_length().
  std::size_t begin_u32_length() {
    const std::size_t at = buf_.size();
    u32(0);
    return at;
  }
  void finish_u32_length(std::size_t at) {
    const auto len = static_cast<std::uint32_t>(buf_.size() - at - 4);
    std::memcpy(buf_.data() + at, &len, 4);
  }
  std::size_t size() const { return buf_.size(); }

 private:
  std::vector<std::byte>& buf_;
};

/// Reads little-endian fields from a span; every read is bounds-checked and a failed read
/// latches ok() = false (and returns zeros), so parsers check once at the end.
class In {
 public:
  explicit In(std::span<const std::byte> b) : b_(b) {}
  std::uint8_t u8() { return get<std::uint8_t>(); }
  std::uint16_t u16() { return get<std::uint16_t>(); }
  std::uint32_t u32() { return get<std::uint32_t>(); }
  std::uint64_t u64() { return get<std::uint64_t>(); }
  std::string str() {
    const std::uint32_t n = u32();
    auto s = take(n);
    return {reinterpret_cast<const char*>(s.data()), s.size()};
  }
  std::span<const std::byte> take(std::uint64_t n) {
    if (!ok_ || n > b_.size() - pos_) {
      ok_ = false;
      return {};
    }
    auto s = b_.subspan(pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return s;
  }
  bool ok() const { return ok_; }
  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return b_.size() - pos_; }

 private:
  template <class T>
  T get() {
    T v{};
    if (!ok_ || sizeof(T) > b_.size() - pos_) {
      ok_ = false;
      return v;
    }
    std::memcpy(&v, b_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::span<const std::byte> b_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

}  // namespace posed::drivers::recording::mcap
