#include "drivers/recording/pcap_parser.hpp"

#include <algorithm>
#include <cstdio>

namespace posed::drivers::recording {
namespace {

constexpr std::uint32_t kPcapMagicUs = 0xA1B2C3D4;
constexpr std::uint32_t kPcapMagicNs = 0xA1B23C4D;
constexpr std::uint32_t kPcapngSectionHeader = 0x0A0D0D0A;
constexpr std::uint32_t kPcapngByteOrderMagic = 0x1A2B3C4D;
constexpr std::uint32_t kPcapngInterface = 1;
constexpr std::uint32_t kPcapngObsoletePacket = 2;
constexpr std::uint32_t kPcapngSimplePacket = 3;
constexpr std::uint32_t kPcapngEnhancedPacket = 6;
constexpr std::size_t kPcapHeaderBytes = 24;
constexpr std::size_t kPcapRecordHeaderBytes = 16;

std::uint32_t bswap32(std::uint32_t v) { return __builtin_bswap32(v); }
/// stamps and offsets beyond ~year 2096 are clamped so their sum cannot overflow int64 ns [s]
constexpr std::int64_t kMaxSeconds = 4'000'000'000;

}  // namespace

std::string_view to_string(PcapStatus s) {
  switch (s) {
    case PcapStatus::kOk:
      return "ok";
    case PcapStatus::kEnd:
      return "end";
    case PcapStatus::kTruncated:
      return "truncated";
    case PcapStatus::kBadMagic:
      return "bad_magic";
    case PcapStatus::kBadBlock:
      return "bad_block";
  }
  return "unknown";
}

std::uint16_t PcapParser::u16(std::size_t at) const {
  const auto* p = file_.data() + at;
  const auto le =
      static_cast<std::uint16_t>(static_cast<unsigned>(p[0]) | (static_cast<unsigned>(p[1]) << 8));
  return swapped_ ? static_cast<std::uint16_t>((le >> 8) | (le << 8)) : le;
}

std::uint32_t PcapParser::u32(std::size_t at) const {
  const auto* p = file_.data() + at;
  const std::uint32_t le =
      static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
      (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
  return swapped_ ? bswap32(le) : le;
}

PcapStatus PcapParser::fail(PcapStatus s, std::uint64_t at, const char* what) {
  error_ = s;
  error_offset_ = at;
  error_what_ = what;
  offset_ = at;
  return s;
}

std::string PcapParser::describe_error() const {
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s at offset %llu (file is %zu bytes)", error_what_,
                static_cast<unsigned long long>(error_offset_), file_.size());
  return buf;
}

PcapStatus PcapParser::open() {
  offset_ = 0;
  swapped_ = false;
  if (file_.size() < 4) return fail(PcapStatus::kTruncated, 0, "file header cut short");
  const std::uint32_t magic = u32(0);
  if (magic == kPcapMagicUs || magic == kPcapMagicNs || bswap32(magic) == kPcapMagicUs ||
      bswap32(magic) == kPcapMagicNs) {
    format_ = CaptureFormat::kPcap;
    swapped_ = magic != kPcapMagicUs && magic != kPcapMagicNs;
    nanosecond_ = magic == kPcapMagicNs || bswap32(magic) == kPcapMagicNs;
    if (file_.size() < kPcapHeaderBytes) {
      return fail(PcapStatus::kTruncated, 0, "pcap file header cut short");
    }
    // The upper bits of the link-type word may carry FCS flags (pcap(5)).
    link_type_ = u32(20) & 0x0FFFFFFF;
    offset_ = kPcapHeaderBytes;
    return PcapStatus::kOk;
  }
  if (magic == kPcapngSectionHeader) {
    format_ = CaptureFormat::kPcapng;
    return PcapStatus::kOk;  // the section header is parsed as the first block
  }
  return fail(PcapStatus::kBadMagic, 0, "not a pcap or pcapng file (bad magic)");
}

PcapStatus PcapParser::next(PcapRecord& out) {
  if (error_ != PcapStatus::kOk) return error_;
  switch (format_) {
    case CaptureFormat::kPcap:
      return next_pcap(out);
    case CaptureFormat::kPcapng:
      return next_pcapng(out);
    case CaptureFormat::kUnknown:
      break;
  }
  return fail(PcapStatus::kBadMagic, 0, "open() was not called or failed");
}

PcapStatus PcapParser::next_pcap(PcapRecord& out) {
  const std::size_t size = file_.size();
  if (offset_ == size) return PcapStatus::kEnd;
  if (size - offset_ < kPcapRecordHeaderBytes) {
    return fail(PcapStatus::kTruncated, offset_, "truncated record header");
  }
  const std::size_t at = static_cast<std::size_t>(offset_);
  const std::uint32_t sec = u32(at), frac = u32(at + 4), incl = u32(at + 8), orig = u32(at + 12);
  if (incl > size - at - kPcapRecordHeaderBytes) {
    return fail(PcapStatus::kTruncated, offset_, "truncated record");
  }
  out.timestamp_ns = static_cast<std::int64_t>(sec) * 1'000'000'000 +
                     (nanosecond_ ? frac : static_cast<std::int64_t>(frac) * 1'000);
  out.link_type = link_type_;
  out.original_length = orig;
  out.frame = file_.subspan(at + kPcapRecordHeaderBytes, incl);
  out.file_offset = offset_;
  offset_ += kPcapRecordHeaderBytes + incl;
  ++counters_.records;
  return PcapStatus::kOk;
}

PcapStatus PcapParser::parse_section_header(std::size_t at, std::uint32_t block_len) {
  if (block_len < 28) return fail(PcapStatus::kBadBlock, at, "section header block too short");
  interface_count_ = 0;
  return PcapStatus::kOk;
}

void PcapParser::parse_interface(std::size_t at, std::uint32_t block_len) {
  if (interface_count_ >= kMaxInterfaces) {
    ++interface_count_;  // packets on it are reported as unknown link type 0xFFFFFFFF
    return;
  }
  Interface& itf = interfaces_[interface_count_++];
  itf = Interface{};
  if (block_len < 20) return;
  itf.link_type = u16(at + 8);
  // Options start after linktype, reserved, snaplen; end before the trailing length.
  std::size_t opt = at + 16;
  const std::size_t end = at + block_len - 4;
  while (opt + 4 <= end) {
    const std::uint16_t code = u16(opt), len = u16(opt + 2);
    const std::size_t value = opt + 4;
    if (code == 0 || value + len > end) break;
    if (code == 9 && len >= 1) {  // if_tsresol
      const auto v = static_cast<std::uint8_t>(file_[value]);
      const unsigned exp = v & 0x7F;
      if ((v & 0x80) != 0) {
        if (exp <= 62) itf.units_per_second = std::uint64_t{1} << exp;
      } else if (exp <= 18) {
        std::uint64_t ups = 1;
        for (unsigned i = 0; i < exp; ++i) ups *= 10;
        itf.units_per_second = ups;
      }
    } else if (code == 14 && len >= 8) {  // if_tsoffset [s]
      itf.offset_s = static_cast<std::int64_t>((static_cast<std::uint64_t>(u32(value + 4)) << 32) |
                                               u32(value));
      if (swapped_) {
        itf.offset_s = static_cast<std::int64_t>((static_cast<std::uint64_t>(u32(value)) << 32) |
                                                 u32(value + 4));
      }
    }
    opt = value + ((len + 3u) & ~3u);
  }
}

PcapStatus PcapParser::next_pcapng(PcapRecord& out) {
  const std::size_t size = file_.size();
  for (;;) {
    if (offset_ == size) return PcapStatus::kEnd;
    const std::size_t at = static_cast<std::size_t>(offset_);
    if (size - at < 12) return fail(PcapStatus::kTruncated, at, "truncated block header");
    // The section header fixes the byte order of everything up to the next one.
    const std::uint32_t raw_type = u32(at);
    if (raw_type == kPcapngSectionHeader || bswap32(raw_type) == kPcapngSectionHeader) {
      const bool was = swapped_;
      swapped_ = false;
      const std::uint32_t bom = u32(at + 8);
      if (bom == kPcapngByteOrderMagic) {
        swapped_ = false;
      } else if (bswap32(bom) == kPcapngByteOrderMagic) {
        swapped_ = true;
      } else {
        swapped_ = was;
        return fail(PcapStatus::kBadBlock, at, "section header with a bad byte-order magic");
      }
    }
    const std::uint32_t type = u32(at);
    const std::uint32_t block_len = u32(at + 4);
    if (block_len < 12 || block_len % 4 != 0) {
      return fail(PcapStatus::kBadBlock, at, "block with an impossible length");
    }
    if (block_len > size - at) return fail(PcapStatus::kTruncated, at, "truncated block");
    if (u32(at + block_len - 4) != block_len) {
      return fail(PcapStatus::kBadBlock, at, "block whose trailing length does not match");
    }
    offset_ += block_len;
    if (type == kPcapngSectionHeader) {
      if (parse_section_header(at, block_len) != PcapStatus::kOk) return error_;
      continue;
    }
    if (type == kPcapngInterface) {
      parse_interface(at, block_len);
      continue;
    }
    std::uint32_t interface_id = 0, cap_len = 0, orig_len = 0;
    std::uint64_t ts = 0;
    std::size_t data = 0;
    if (type == kPcapngEnhancedPacket || type == kPcapngObsoletePacket) {
      if (block_len < 32) return fail(PcapStatus::kBadBlock, at, "packet block too short");
      interface_id = type == kPcapngEnhancedPacket ? u32(at + 8) : u16(at + 8);
      ts = (static_cast<std::uint64_t>(u32(at + 12)) << 32) | u32(at + 16);
      cap_len = u32(at + 20);
      orig_len = u32(at + 24);
      data = at + 28;
      if (cap_len > block_len - 32) {
        return fail(PcapStatus::kBadBlock, at, "packet block whose data overruns it");
      }
    } else if (type == kPcapngSimplePacket) {
      if (block_len < 16) return fail(PcapStatus::kBadBlock, at, "simple packet block too short");
      orig_len = u32(at + 8);
      cap_len = orig_len < block_len - 16 ? orig_len : block_len - 16;
      data = at + 12;
    } else {
      ++counters_.skipped_blocks;
      continue;
    }
    if (interface_count_ == 0) {
      return fail(PcapStatus::kBadBlock, at, "packet block before any interface description");
    }
    out.link_type = 0xFFFFFFFF;
    out.timestamp_ns = 0;
    if (interface_id < interface_count_ && interface_id < kMaxInterfaces) {
      const Interface& itf = interfaces_[interface_id];
      out.link_type = itf.link_type;
      if (type == kPcapngSimplePacket) {
        out.timestamp_ns = last_timestamp_ns_;  // simple packets carry no time
      } else {
        const std::uint64_t ups = itf.units_per_second;
        // Saturate far-future stamps (a corrupt file) instead of overflowing int64 ns.
        const std::uint64_t sec = std::min<std::uint64_t>(ts / ups, kMaxSeconds);
        const std::uint64_t frac = ts % ups;
        const std::int64_t offset_s =
            std::clamp<std::int64_t>(itf.offset_s, -kMaxSeconds, kMaxSeconds);
        out.timestamp_ns = (static_cast<std::int64_t>(sec) + offset_s) * 1'000'000'000 +
                           static_cast<std::int64_t>(static_cast<long double>(frac) * 1e9L /
                                                     static_cast<long double>(ups));
        last_timestamp_ns_ = out.timestamp_ns;
      }
    }
    out.original_length = orig_len;
    out.frame = file_.subspan(data, cap_len);
    out.file_offset = at;
    ++counters_.records;
    return PcapStatus::kOk;
  }
}

}  // namespace posed::drivers::recording
