#pragma once
// What a recording holds and what is wrong with it, as data (`posectl inspect FILE.mcap` prints
// it): per channel the message count, rate [Hz], time span, typical period and the largest gaps
// against it (where: log time and file offset), and for the file its summary state, where a
// damaged file stops, every issue with its offset, and the records skipped for their opcode.
//
// One linear pass with McapReader; memory grows by 8 B per message (the intervals, for the
// median period and the gap count).

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/time.hpp"
#include "drivers/recording/mcap_reader.hpp"

namespace posed::drivers::recording {

struct McapGap {
  /// log time of the message before the gap [ns]
  std::uint64_t after_log_ns = 0;
  /// time between that message and the next on the channel [ns]
  std::int64_t length_ns = 0;
  /// file offset of the record holding the message after the gap (its Chunk) [B]
  std::uint64_t record_offset = 0;
};

struct McapChannelStats {
  McapChannelRecord channel;
  /// the schema's name, "" without one, "MISSING" when the channel names an undefined schema
  std::string schema_name;
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;  ///< payload [B]
  std::uint64_t first_log_ns = 0, last_log_ns = 0;
  /// (messages - 1) / span; 0 with fewer than two messages [Hz]
  double rate_hz = 0;
  /// median interval between consecutive messages: the channel's typical period [ns]
  std::int64_t median_interval_ns = 0;
  /// intervals longer than gap_factor x the median
  std::uint64_t gaps = 0;
  /// the longest of those, longest first (at most McapInspectOptions::max_gaps)
  std::vector<McapGap> largest_gaps;
  /// messages logged before the channel's previous one
  std::uint64_t out_of_order = 0;

  double span_s() const { return static_cast<double>(last_log_ns - first_log_ns) * 1e-9; }
};

struct McapInspection {
  std::uint64_t file_size_bytes = 0;
  std::string profile, library;
  /// every channel the file defines, by id, with or without messages
  std::vector<McapChannelStats> channels;
  std::uint64_t messages = 0;
  /// earliest and latest log time over all messages [ns]
  std::uint64_t first_log_ns = 0, last_log_ns = 0;
  /// wall minus host time from the recording's "posed" metadata, when present
  std::optional<HostToWall> host_to_wall;
  McapSummaryInfo summary;
  McapReaderCounters counters;
  /// the scan reached DataEnd with no bad chunk or record
  bool complete = false;
  /// "" when complete, else why and where reading stopped
  std::string stop_reason;
  std::vector<McapIssue> issues;
  std::vector<McapUnknownRecord> unknown_records;
};

struct McapInspectOptions {
  /// an interval longer than this times the channel's median period is a gap
  double gap_factor = 3.0;
  /// gaps listed per channel
  std::size_t max_gaps = 3;
  bool verify_crcs = true;
  /// called now and then with the scan's file offset [B]; may be empty
  std::function<void(std::uint64_t offset)> progress;
};

/// false + `error` only when the file is not MCAP at all; damage is in the result.
bool inspect_mcap(const std::string& path, const McapInspectOptions& options, McapInspection& out,
                  std::string& error);
/// The same over bytes in memory (tests, fuzzing).
bool inspect_mcap_bytes(std::span<const std::byte> bytes, const McapInspectOptions& options,
                        McapInspection& out, std::string& error);

}  // namespace posed::drivers::recording
