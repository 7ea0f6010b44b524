#pragma once
// A pure reader of capture files: classic pcap (microsecond and nanosecond, either byte order)
// and pcapng (Section Header, Interface Description, Enhanced/Simple/obsolete Packet blocks;
// every other block type skipped), over bytes already in memory. It never throws and never
// reads outside the span: a record cut short is reported as kTruncated with its file offset.
// References: tcpdump.org "pcap savefile format" (pcap(5)); IETF draft-ietf-opsawg-pcapng.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace posed::drivers::recording {

enum class CaptureFormat : std::uint8_t { kUnknown, kPcap, kPcapng };

enum class PcapStatus : std::uint8_t {
  kOk,         ///< a record was returned
  kEnd,        ///< clean end of file
  kTruncated,  ///< the file ends inside a header or record (offset says where)
  kBadMagic,   ///< not a pcap or pcapng file
  kBadBlock,   ///< a pcapng block with an impossible length, or a packet before any interface
};

std::string_view to_string(PcapStatus s);

/// One captured frame.
struct PcapRecord {
  /// capture time [ns since the UNIX epoch]
  std::int64_t timestamp_ns = 0;
  /// LINKTYPE_* of the interface (1 Ethernet, 113 Linux SLL, 276 SLL2, 101 raw IP, ...)
  std::uint32_t link_type = 0;
  /// length on the wire [B]; more than frame.size() when the capture was cut at snaplen
  std::uint32_t original_length = 0;
  /// the captured bytes, pointing into the parsed span
  std::span<const std::byte> frame;
  /// offset of the record's header in the file [B]
  std::uint64_t file_offset = 0;
};

struct PcapParserCounters {
  std::uint64_t records = 0;
  /// pcapng blocks of types this reader does not use (statistics, name resolution, ...)
  std::uint64_t skipped_blocks = 0;
};

class PcapParser {
 public:
  explicit PcapParser(std::span<const std::byte> file) : file_(file) {}

  /// Reads the file header. kOk, kBadMagic or kTruncated.
  PcapStatus open();
  /// The next record; kEnd at a clean end.
  PcapStatus next(PcapRecord& out);

  CaptureFormat format() const { return format_; }
  /// where the parser stopped: the offset of the next (or the failing) header [B]
  std::uint64_t offset() const { return offset_; }
  /// A sentence for the last failure: "truncated record at offset 1234 (file is 1300 bytes)".
  std::string describe_error() const;
  const PcapParserCounters& counters() const { return counters_; }

 private:
  std::uint16_t u16(std::size_t at) const;
  std::uint32_t u32(std::size_t at) const;
  PcapStatus next_pcap(PcapRecord& out);
  PcapStatus next_pcapng(PcapRecord& out);
  PcapStatus parse_section_header(std::size_t at, std::uint32_t block_len);
  void parse_interface(std::size_t at, std::uint32_t block_len);
  PcapStatus fail(PcapStatus s, std::uint64_t at, const char* what);

  std::span<const std::byte> file_;
  CaptureFormat format_ = CaptureFormat::kUnknown;
  bool swapped_ = false;
  std::uint64_t offset_ = 0;
  PcapParserCounters counters_;
  // classic pcap
  std::uint32_t link_type_ = 0;
  bool nanosecond_ = false;
  // pcapng: interfaces of the current section (more than 16 are counted as unknown)
  struct Interface {
    std::uint32_t link_type = 0;
    /// timestamp units per second (10^6 unless if_tsresol says otherwise)
    std::uint64_t units_per_second = 1'000'000;
    /// if_tsoffset [s]
    std::int64_t offset_s = 0;
  };
  static constexpr std::size_t kMaxInterfaces = 16;
  std::array<Interface, kMaxInterfaces> interfaces_{};
  std::size_t interface_count_ = 0;
  /// the previous packet's time, for Simple Packet Blocks (which carry none) [ns]
  std::int64_t last_timestamp_ns_ = 0;
  // last failure
  PcapStatus error_ = PcapStatus::kOk;
  std::uint64_t error_offset_ = 0;
  const char* error_what_ = "";
};

}  // namespace posed::drivers::recording
