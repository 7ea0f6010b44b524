#pragma once
// The record layer of the ROS bag format 2.0 (wiki.ros.org/Bags/Format/2.0): after the line
// "#ROSBAG V2.0\n" a bag is a sequence of records
//
//   <header_len u32><header: fields><data_len u32><data>
//   field = <field_len u32><name>=<value>     (field_len counts name, '=' and value)
//
// all integers little-endian. Every header has an `op` field (one byte) saying what the record
// is. Connection records carry a second field list (the connection header: topic, type, md5sum,
// message_definition, callerid, latching) as their data, parsed the same way.
//
// Pure and allocation-free: records and fields are spans into the caller's bytes; a length that
// runs past the end is a status, never a read outside the span.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace posed::drivers::recording::ros1 {

/// The first 13 bytes of every bag of format 2.0.
inline constexpr std::string_view kBagMagic = "#ROSBAG V2.0\n";

/// Record kinds (the header's `op` field).
enum class BagOp : std::uint8_t {
  kMessageData = 0x02,  ///< conn, time; data = one serialized message
  kBagHeader = 0x03,    ///< index_pos, conn_count, chunk_count; data = padding
  kIndexData = 0x04,    ///< ver, conn, count; data = count x (time, offset in chunk)
  kChunk = 0x05,        ///< compression, size; data = compressed records
  kChunkInfo = 0x06,    ///< ver, chunk_pos, start_time, end_time, count; data = (conn, count)s
  kConnection = 0x07,   ///< conn, topic; data = the connection header fields
};

/// "MessageData", "Chunk", ...; "unknown" for anything else.
std::string_view op_name(std::uint8_t op);

/// One record, as spans into the bytes it was read from.
struct BagRecord {
  std::span<const std::byte> header;  ///< the field list
  std::span<const std::byte> data;
  /// bytes the record occupies: 8 + header_len + data_len [B]
  std::uint64_t size_bytes = 0;
};

enum class RecordStatus : std::uint8_t {
  kOk,
  kTruncated,  ///< the bytes end inside the record (`needed` says how many it wants)
};

/// Reads the record that starts at `at`. On kTruncated `needed` holds the bytes the record would
/// need from `at` (at least the 4 or 8 of its length words) [B].
RecordStatus read_record(std::span<const std::byte> bytes, std::uint64_t at, BagRecord& out,
                         std::uint64_t& needed);

/// A record header's (or a connection header's) fields, as views into its bytes.
class RecordFields {
 public:
  /// Most fields kept; a bag's headers have at most 6. Further fields are counted, not kept.
  static constexpr std::size_t kMaxFields = 24;

  /// Splits `header` into fields. false and `error` ("field 2 at +40: length 300 runs past the
  /// header (64 B)") when a length runs past the end or a field has no '='.
  bool parse(std::span<const std::byte> header, std::string& error);

  /// The value of field `name`; nullopt when absent.
  std::optional<std::span<const std::byte>> find(std::string_view name) const;
  /// Typed lookups: false when absent or of the wrong size (an op is 1 byte, u32 4, u64 and
  /// time 8; a time is sec u32 then nsec u32, returned as ns).
  bool get_u8(std::string_view name, std::uint8_t& out) const;
  bool get_u32(std::string_view name, std::uint32_t& out) const;
  bool get_u64(std::string_view name, std::uint64_t& out) const;
  bool get_time_ns(std::string_view name, std::uint64_t& out) const;
  /// Any bytes as text (topic, type, compression); false when absent.
  bool get_string(std::string_view name, std::string_view& out) const;

  std::size_t size() const { return count_; }
  std::string_view name(std::size_t i) const { return fields_[i].name; }
  std::span<const std::byte> value(std::size_t i) const { return fields_[i].value; }
  /// fields beyond kMaxFields (not kept)
  std::size_t dropped() const { return dropped_; }

 private:
  struct Field {
    std::string_view name;
    std::span<const std::byte> value;
  };
  std::array<Field, kMaxFields> fields_{};
  std::size_t count_ = 0;
  std::size_t dropped_ = 0;
};

/// Little-endian loads from unaligned bytes (the caller checked the size).
std::uint32_t load_u32(const std::byte* p);
std::uint64_t load_u64(const std::byte* p);
/// A ROS time (sec u32, nsec u32) as ns.
std::uint64_t load_time_ns(const std::byte* p);

}  // namespace posed::drivers::recording::ros1
