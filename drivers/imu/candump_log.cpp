#include "drivers/imu/candump_log.hpp"

#include <cstring>
#include <limits>
#include <utility>

#include "drivers/common/log.hpp"

namespace posed::drivers::can {
namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool fail(std::string& error, std::string_view line, std::size_t col, const char* what) {
  error = "column " + std::to_string(col + 1) + ": " + what + " in '" + std::string(line) + "'";
  return false;
}

}  // namespace

bool parse_candump_line(std::string_view line, CandumpRecord& record, std::string& error) {
  record = CandumpRecord{};
  std::size_t i = 0;
  // (seconds.micro)
  if (line.empty() || line[0] != '(') return fail(error, line, 0, "expected '('");
  ++i;
  std::int64_t sec = 0;
  const std::size_t sec_start = i;
  while (i < line.size() && line[i] >= '0' && line[i] <= '9' && i - sec_start < 12) {
    sec = sec * 10 + (line[i++] - '0');
  }
  if (i == sec_start || i >= line.size() || line[i] != '.') {
    return fail(error, line, i, "expected seconds.fraction");
  }
  // The stamp is held in int64 nanoseconds: up to 2^63 ns, year 2262.
  if (sec > std::numeric_limits<std::int64_t>::max() / 1'000'000'000 - 1) {
    return fail(error, line, sec_start, "timestamp beyond 2^63 ns");
  }
  ++i;
  std::int64_t frac_ns = 0, scale = 100'000'000;
  const std::size_t frac_start = i;
  while (i < line.size() && line[i] >= '0' && line[i] <= '9') {
    if (scale > 0) frac_ns += (line[i] - '0') * scale;
    scale /= 10;
    ++i;
  }
  if (i == frac_start || i >= line.size() || line[i] != ')') {
    return fail(error, line, i, "expected fraction and ')'");
  }
  record.stamp_ns = sec * 1'000'000'000 + frac_ns;
  ++i;
  // interface
  while (i < line.size() && line[i] == ' ') ++i;
  const std::size_t if_start = i;
  while (i < line.size() && line[i] != ' ') ++i;
  const std::size_t if_len = i - if_start;
  if (if_len == 0 || if_len >= record.interface.size()) {
    return fail(error, line, if_start, "bad interface name");
  }
  // Printable ASCII only: the name is kept NUL-terminated, and a NUL or control byte in it
  // (a binary file read as a log) would cut or garble it.
  for (std::size_t k = if_start; k < i; ++k) {
    if (line[k] <= ' ' || line[k] > '~') return fail(error, line, k, "bad interface name");
  }
  std::memcpy(record.interface.data(), line.data() + if_start, if_len);
  while (i < line.size() && line[i] == ' ') ++i;
  // ID
  const std::size_t id_start = i;
  std::uint32_t id = 0;
  while (i < line.size() && line[i] != '#') {
    const int v = hex_value(line[i]);
    if (v < 0) return fail(error, line, i, "bad hex digit in ID");
    id = (id << 4) | static_cast<std::uint32_t>(v);
    ++i;
  }
  const std::size_t id_len = i - id_start;
  if (i >= line.size()) return fail(error, line, i, "missing '#'");
  CanFrame& f = record.frame;
  if (id_len == 3) {
    if (id > 0x7FF) return fail(error, line, id_start, "standard ID above 0x7FF");
    f.id = id;
  } else if (id_len == 8) {
    if ((id & 0x20000000u) != 0) {  // CAN_ERR_FLAG: an error frame, not an extended ID
      f.error = true;
      f.id = id & 0x1FFFFFFFu;
    } else {
      if (id > 0x1FFFFFFFu) return fail(error, line, id_start, "extended ID above 29 bits");
      f.extended = true;
      f.id = id;
    }
  } else {
    return fail(error, line, id_start, "ID must have 3 or 8 hex digits");
  }
  ++i;  // '#'
  std::size_t max_len = 8;
  if (i < line.size() && line[i] == '#') {
    ++i;
    const int flags = i < line.size() ? hex_value(line[i]) : -1;
    if (flags < 0) return fail(error, line, i, "CAN FD frame needs a flags nibble after '##'");
    f.fd = true;
    f.fd_flags = static_cast<std::uint8_t>(flags);
    max_len = 64;
    ++i;
  } else if (i < line.size() && (line[i] == 'R' || line[i] == 'r')) {
    f.remote = true;
    ++i;
    if (i < line.size() && line[i] >= '0' && line[i] <= '8')
      f.len = static_cast<std::uint8_t>(line[i++] - '0');
    while (i < line.size() && (line[i] == ' ' || line[i] == '\r')) ++i;
    if (i != line.size()) return fail(error, line, i, "unexpected text after remote frame");
    return true;
  }
  std::size_t len = 0;
  while (i < line.size() && line[i] != '_' && line[i] != ' ' && line[i] != '\r') {
    if (line[i] == '.') {
      ++i;
      continue;
    }
    const int hi = hex_value(line[i]);
    const int lo = i + 1 < line.size() ? hex_value(line[i + 1]) : -1;
    if (hi < 0 || lo < 0) return fail(error, line, i, "bad hex byte in data");
    if (len >= max_len) return fail(error, line, i, "too many data bytes");
    f.data[len++] = static_cast<std::uint8_t>((hi << 4) | lo);
    i += 2;
  }
  if (f.fd && !is_valid_fd_len(len)) return fail(error, line, i, "invalid CAN FD length");
  if (i < line.size() && line[i] == '_') {
    // Classic "len8_dlc" hint: a DLC of 9..15 for 8 data bytes; the data is what matters.
    if (f.fd || len != 8 || i + 1 >= line.size() || hex_value(line[i + 1]) < 9) {
      return fail(error, line, i, "bad '_' DLC suffix");
    }
    i += 2;
  }
  while (i < line.size() && (line[i] == ' ' || line[i] == '\r')) ++i;
  if (i != line.size()) return fail(error, line, i, "unexpected text after data");
  f.len = static_cast<std::uint8_t>(len);
  return true;
}

CandumpReplaySource::CandumpReplaySource(std::string path, std::string name)
    : path_(std::move(path)), name_(std::move(name)) {}

bool CandumpReplaySource::open(std::string& error) {
  if (in_.is_open()) return true;
  in_.open(path_);
  if (!in_) {
    error = "candump log " + path_ + ": cannot open: " + std::strerror(errno);
    return false;
  }
  return true;
}

ReadStatus CandumpReplaySource::read(RawChunk& chunk, Duration /*timeout*/) {
  if (stop_ || !in_.is_open()) return ReadStatus::kEndOfStream;
  std::string error;
  while (std::getline(in_, line_)) {
    ++line_no_;
    if (line_.empty() || line_ == "\r") continue;
    if (!parse_candump_line(line_, record_, error)) {
      if (++counters_.rejected <= 10) {
        POSED_LOG_WARN("%s: %s line %llu: %s", name_.c_str(), path_.c_str(),
                       static_cast<unsigned long long>(line_no_), error.c_str());
      }
      continue;
    }
    const std::size_t n = to_kernel_bytes(record_.frame, buffer_);
    if (n == 0) {
      ++counters_.rejected;
      continue;
    }
    chunk.bytes = std::as_bytes(std::span<const std::uint8_t>(buffer_.data(), n));
    chunk.host_receive = HostTime::from_ns(record_.stamp_ns);
    chunk.channel = 0;
    ++counters_.chunks;
    counters_.bytes += n;
    return ReadStatus::kData;
  }
  return ReadStatus::kEndOfStream;
}

}  // namespace posed::drivers::can
