#pragma once
// can-utils candump log format (`candump -l`, `log2asc` input), one frame per line:
//   (1600000000.123456) can0 123#DEADBEEF        standard ID, classic data
//   (1600000000.123456) can0 12345678#DE.AD      extended ID (8 hex digits), '.' separators
//   (1600000000.123456) can0 123##1DEADBEEF      CAN FD: '##', one hex flags nibble, data
//   (1600000000.123456) can0 123#R  / 123#R4     remote frame, optional requested length
//   (1600000000.123456) can0 20000004#00040000   error frame (CAN_ERR_FLAG in the 8-digit ID)
//   (...) can0 123#1122334455667788_E            classic frame with a DLC > 8 hint (ignored)
// Parsing is pure; CandumpReplaySource replays a file as a Source of kernel-format frames.

#include <array>
#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>

#include "drivers/common/source.hpp"
#include "drivers/common/wire_format.hpp"
#include "drivers/imu/can_frame.hpp"

namespace posed::drivers::can {

struct CandumpRecord {
  /// the log's timestamp, as written (candump uses the wall clock) [ns]
  std::int64_t stamp_ns = 0;
  /// interface name as logged ("can0"), NUL-terminated
  std::array<char, 16> interface {};
  CanFrame frame;
};

/// Parses one log line. On failure returns false and says why in `error` (with the column).
bool parse_candump_line(std::string_view line, CandumpRecord& record, std::string& error);

/// Replays a candump log: each read() returns one frame in kernel byte form (see can_frame.hpp)
/// with the log timestamp as host_receive, as fast as the caller reads. Malformed lines are
/// counted as rejected and logged with file and line number (the first 10).
class CandumpReplaySource final : public Source {
 public:
  explicit CandumpReplaySource(std::string path, std::string name = "imu_can");
  std::string_view name() const override { return name_; }
  std::string_view wire_format(std::uint32_t channel) const override {
    return channel == 0 ? wire::kCanFrame : std::string_view{};
  }
  bool open(std::string& error) override;
  ReadStatus read(RawChunk& chunk, Duration timeout) override;
  void request_stop() override { stop_ = true; }
  SourceCounters counters() const override { return counters_; }
  /// the record of the last frame read() returned (interface, timestamp)
  const CandumpRecord& last_record() const { return record_; }

 private:
  std::string path_;
  std::string name_;
  std::ifstream in_;
  std::string line_;
  std::uint64_t line_no_ = 0;
  CandumpRecord record_;
  std::array<std::uint8_t, kCanFdMtu> buffer_{};
  SourceCounters counters_;
  bool stop_ = false;
};

}  // namespace posed::drivers::can
