// posectl inspect FILE.mcap (or posectl inspect mcap FILE): what a recording holds and what is
// wrong with it (drivers/recording/mcap_inspection.hpp). Per channel: topic, encoding, schema,
// stream and wire format for raw channels, message count, bytes, rate [Hz], time span [s],
// typical period and the largest gaps against it with where they are (log time and file
// offset). Then the file's state: summary present and valid, chunks decoded and bad, where a
// damaged file stops, every issue with its byte offset, and records skipped for their opcode.
// Exit codes: 0 complete, 1 damaged or not MCAP, 2 bad arguments.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <ctime>
#include <string>

#include "drivers/recording/mcap_inspection.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {

namespace rec = drivers::recording;

namespace {

unsigned long long ull(std::uint64_t v) { return static_cast<unsigned long long>(v); }

/// "2024-06-01 12:00:00.000 UTC"
std::string utc(WallTime t) {
  const std::time_t s = static_cast<std::time_t>(t.ns / 1'000'000'000);
  std::tm tm{};
  ::gmtime_r(&s, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02d %02d:%02d:%02d.%03d UTC", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                static_cast<int>((t.ns % 1'000'000'000) / 1'000'000));
  return buf;
}

void print_channel(const rec::McapChannelStats& s, const rec::McapInspection& r,
                   double gap_factor) {
  const rec::McapChannelRecord& c = s.channel;
  std::printf("\nchannel %u  %s\n", c.id, c.topic.c_str());
  std::printf("  format   encoding %s, %s", c.message_encoding.c_str(),
              c.schema_id == 0 ? "no schema" : ("schema " + s.schema_name).c_str());
  if (c.message_encoding == rec::raw::kMessageEncoding) {
    std::printf("; stream %s, wire format %s, source channel %s",
                rec::raw::metadata_value(c.metadata, rec::raw::kStreamKey).c_str(),
                rec::raw::metadata_value(c.metadata, rec::raw::kWireFormatKey).c_str(),
                rec::raw::metadata_value(c.metadata, rec::raw::kSourceChannelKey).c_str());
  }
  std::printf("\n");
  if (s.messages == 0) {
    std::printf("  messages 0\n");
    return;
  }
  const auto since_start = [&](std::uint64_t log_ns) {
    return static_cast<double>(log_ns - r.first_log_ns) * 1e-9;
  };
  std::printf(
      "  messages %llu, %.3f MB (%.0f B each), %.3f Hz over %.3f s (from +%.3f s to +%.3f s)\n",
      ull(s.messages), static_cast<double>(s.bytes) / 1e6,
      static_cast<double>(s.bytes) / static_cast<double>(s.messages), s.rate_hz, s.span_s(),
      since_start(s.first_log_ns), since_start(s.last_log_ns));
  if (s.messages < 2) return;
  std::printf("  period   %.3f ms typical (median interval); %llu gap%s longer than %gx (%.3f ms)",
              static_cast<double>(s.median_interval_ns) * 1e-6, ull(s.gaps), s.gaps == 1 ? "" : "s",
              gap_factor, gap_factor * static_cast<double>(s.median_interval_ns) * 1e-6);
  if (s.out_of_order > 0) {
    std::printf("; %llu message%s logged before the previous one", ull(s.out_of_order),
                s.out_of_order == 1 ? "" : "s");
  }
  std::printf("\n");
  for (const rec::McapGap& g : s.largest_gaps) {
    std::printf(
        "  gap      %.3f ms (%.1fx the period) after +%.3f s (log time %.9f s), next message "
        "in the record at offset %llu B\n",
        static_cast<double>(g.length_ns) * 1e-6,
        static_cast<double>(g.length_ns) / static_cast<double>(s.median_interval_ns),
        since_start(g.after_log_ns), static_cast<double>(g.after_log_ns) * 1e-9,
        ull(g.record_offset));
  }
}

}  // namespace

int run_inspect_mcap(int argc, char** argv) {
  CLI::App app{
      "Lists an MCAP recording's channels with message counts, rates [Hz], time spans [s], "
      "typical periods and the largest gaps (with their log time and file offset), then the "
      "file's state (summary, CRCs, where a damaged file stops) and every problem found with "
      "its byte offset. Also: posectl inspect FILE.mcap.",
      "posectl inspect mcap"};
  std::string path;
  rec::McapInspectOptions options;
  bool no_crc = false;
  app.add_option("FILE", path, "MCAP recording")->required();
  app.add_option("--gap-factor", options.gap_factor,
                 "an interval longer than this times the channel's median interval is a gap")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--gaps", options.max_gaps, "largest gaps listed per channel")
      ->capture_default_str();
  app.add_flag("--no-crc", no_crc, "skip CRC checks (faster on huge files)");
  CLI11_PARSE(app, argc, argv);
  options.verify_crcs = !no_crc;

  std::uint64_t size = 0;
  bool progressed = false;
  {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (f != nullptr) {
      std::fseek(f, 0, SEEK_END);
      size = static_cast<std::uint64_t>(std::ftell(f));
      std::fclose(f);
    }
  }
  options.progress = [&](std::uint64_t offset) {
    if (size == 0) return;
    progressed = true;
    std::fprintf(stderr, "\rposectl inspect: %.0f %% of %.1f MB read",
                 100.0 * static_cast<double>(offset) / static_cast<double>(size),
                 static_cast<double>(size) / 1e6);
  };
  rec::McapInspection r;
  std::string error;
  const bool ok = rec::inspect_mcap(path, options, r, error);
  if (progressed) std::fprintf(stderr, "\n");
  if (!ok) {
    std::fprintf(stderr, "posectl inspect: %s\n", error.c_str());
    return 1;
  }

  std::printf("file       %s: %.3f MB (%llu B), profile '%s', library '%s'\n", path.c_str(),
              static_cast<double>(r.file_size_bytes) / 1e6, ull(r.file_size_bytes),
              r.profile.c_str(), r.library.c_str());
  if (r.messages > 0) {
    std::printf("time span  %.3f s of log time (log time %.9f s to %.9f s)",
                static_cast<double>(r.last_log_ns - r.first_log_ns) * 1e-9,
                static_cast<double>(r.first_log_ns) * 1e-9,
                static_cast<double>(r.last_log_ns) * 1e-9);
    if (r.host_to_wall) {
      const auto wall = [&](std::uint64_t log_ns) {
        return (*r.host_to_wall)(HostTime::from_ns(static_cast<std::int64_t>(log_ns)));
      };
      std::printf(", recorded %s to %s", utc(wall(r.first_log_ns)).c_str(),
                  utc(wall(r.last_log_ns)).c_str());
    }
    std::printf("\n");
  }
  std::printf("contents   %zu channels, %llu messages\n", r.channels.size(), ull(r.messages));
  for (const auto& s : r.channels) print_channel(s, r, options.gap_factor);

  const auto& sum = r.summary;
  const auto& c = r.counters;
  std::printf("\nfile state\n");
  std::printf("  summary  %s", !sum.footer_found ? "missing (no Footer: file cut short?)"
                               : !sum.present    ? "none (Footer without a summary section)"
                               : sum.usable()    ? "present, CRC ok"
                                                 : "present but unusable (see errors)");
  if (sum.usable() && sum.has_statistics) {
    std::printf(" (statistics: %llu messages, %u chunks)", ull(sum.message_count), sum.chunk_count);
  }
  std::printf("\n  chunks   %llu decoded, %llu bad (CRC, compression, size)\n", ull(c.chunks),
              ull(c.chunks_bad));
  std::printf(
      "  records  %llu malformed, %llu unknown (skipped as the spec says), %llu messages on "
      "an undefined channel\n",
      ull(c.bad_records), ull(c.unknown_records), ull(c.orphan_messages));
  std::printf("  state    %s\n", r.complete ? "complete" : ("damaged: " + r.stop_reason).c_str());
  const std::uint64_t problems = c.issues + c.unknown_records;
  if (problems > 0) std::printf("\nerrors (%llu)\n", ull(problems));
  for (const auto& i : r.issues) {
    std::printf("  offset %llu B: %s\n", ull(i.offset), i.what.c_str());
  }
  if (c.issues > r.issues.size()) {
    std::printf("  ... and %llu more issues\n", ull(c.issues - r.issues.size()));
  }
  for (const auto& u : r.unknown_records) {
    char where[96] = "";
    if (u.chunk_byte >= 0) {
      std::snprintf(where, sizeof where, " (inside the Chunk, at byte %lld of its records)",
                    static_cast<long long>(u.chunk_byte));
    }
    std::printf("  offset %llu B%s: unknown record opcode 0x%02x (%llu B): skipped\n",
                ull(u.offset), where, u.opcode, ull(u.length));
  }
  if (c.unknown_records > r.unknown_records.size()) {
    std::printf("  ... and %llu more unknown records\n",
                ull(c.unknown_records - r.unknown_records.size()));
  }
  return r.complete ? 0 : 1;
}

}  // namespace posed::posectl
