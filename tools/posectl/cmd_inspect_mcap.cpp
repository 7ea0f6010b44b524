// posectl inspect mcap FILE.mcap: what a recording holds. Channels (topic, encoding, schema,
// stream and wire format for raw channels), per channel message count, rate [Hz], time span [s],
// bytes, gaps (an interval over 3x the channel's median), then the file's state: summary present
// and valid, where a damaged file stops, and every issue with its offset.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {

namespace rec = drivers::recording;

namespace {

struct ChannelStats {
  std::uint64_t count = 0;
  std::uint64_t bytes = 0;
  std::uint64_t first_ns = 0, last_ns = 0;
  std::vector<std::int64_t> intervals_ns;
  std::uint64_t out_of_order = 0;
};

std::string meta(const rec::McapChannelRecord& c, std::string_view key) {
  const auto it = c.metadata.find(std::string(key));
  return it == c.metadata.end() ? std::string() : it->second;
}

}  // namespace

int run_inspect_mcap(int argc, char** argv) {
  CLI::App app{
      "Lists an MCAP recording's channels with message counts, rates [Hz], time spans [s] and\n"
      "gaps, then the file's state (summary, CRCs) and every problem found, with its offset.",
      "posectl inspect mcap"};
  std::string path;
  double gap_factor = 3.0;
  bool no_crc = false;
  app.add_option("FILE", path, "MCAP recording")->required();
  app.add_option("--gap-factor", gap_factor,
                 "report intervals longer than this times the channel's median interval")
      ->check(CLI::PositiveNumber);
  app.add_flag("--no-crc", no_crc, "skip CRC checks (faster on huge files)");
  CLI11_PARSE(app, argc, argv);

  rec::McapReader reader;
  std::string error;
  rec::McapReaderOptions options;
  options.verify_crcs = !no_crc;
  if (!reader.open(path, error, options)) {
    std::fprintf(stderr, "posectl inspect mcap: %s\n", error.c_str());
    return 1;
  }
  std::map<std::uint16_t, ChannelStats> stats;
  rec::McapMessage m;
  std::uint64_t n = 0;
  const std::uint64_t size = reader.file_size_bytes();
  while (reader.next(m)) {
    auto& s = stats[m.channel->id];
    if (s.count > 0) {
      const auto d = static_cast<std::int64_t>(m.log_time_ns - s.last_ns);
      if (m.log_time_ns < s.last_ns) ++s.out_of_order;
      s.intervals_ns.push_back(d);
    } else {
      s.first_ns = m.log_time_ns;
    }
    s.last_ns = m.log_time_ns;
    ++s.count;
    s.bytes += m.data.size();
    if ((++n & 0xFFFFF) == 0 && size > 0) {
      std::fprintf(stderr, "\rposectl inspect mcap: %.0f %% (%llu messages)",
                   100.0 * static_cast<double>(reader.offset()) / static_cast<double>(size),
                   static_cast<unsigned long long>(n));
    }
  }
  if (n > 0xFFFFF) std::fprintf(stderr, "\n");

  std::printf("file: %s (%llu B) profile='%s' library='%s'\n", path.c_str(),
              static_cast<unsigned long long>(size), reader.profile().c_str(),
              reader.library().c_str());
  for (const auto& [id, c] : reader.channels()) {
    const auto it = stats.find(id);
    const ChannelStats empty;
    const ChannelStats& s = it == stats.end() ? empty : it->second;
    const double span_s = s.count > 1 ? static_cast<double>(s.last_ns - s.first_ns) * 1e-9 : 0.0;
    const double rate_hz = span_s > 0 ? static_cast<double>(s.count - 1) / span_s : 0.0;
    const auto* schema = reader.schema(c.schema_id);
    std::printf("channel %u %s encoding=%s schema=%s", id, c.topic.c_str(),
                c.message_encoding.c_str(),
                c.schema_id == 0 ? "none" : (schema ? schema->name.c_str() : "MISSING"));
    if (c.message_encoding == rec::raw::kMessageEncoding) {
      std::printf(" stream=%s wire_format=%s source_channel=%s",
                  meta(c, rec::raw::kStreamKey).c_str(), meta(c, rec::raw::kWireFormatKey).c_str(),
                  meta(c, rec::raw::kSourceChannelKey).c_str());
    }
    std::printf("\n  messages=%llu bytes=%llu B rate=%.3f Hz span=%.3f s start=%.9f s end=%.9f s\n",
                static_cast<unsigned long long>(s.count), static_cast<unsigned long long>(s.bytes),
                rate_hz, span_s, static_cast<double>(s.first_ns) * 1e-9,
                static_cast<double>(s.last_ns) * 1e-9);
    if (s.intervals_ns.size() >= 2) {
      std::vector<std::int64_t> sorted = s.intervals_ns;
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2),
                       sorted.end());
      const std::int64_t median = sorted[sorted.size() / 2];
      std::uint64_t gaps = 0;
      std::int64_t largest = 0;
      std::uint64_t largest_at = 0, t = s.first_ns;
      for (std::int64_t d : s.intervals_ns) {
        if (median > 0 && static_cast<double>(d) > gap_factor * static_cast<double>(median)) {
          ++gaps;
          if (d > largest) {
            largest = d;
            largest_at = t;
          }
        }
        t += static_cast<std::uint64_t>(d);
      }
      std::printf("  median interval=%.3f ms gaps=%llu", static_cast<double>(median) * 1e-6,
                  static_cast<unsigned long long>(gaps));
      if (gaps > 0) {
        std::printf(" largest=%.3f ms after log time %.9f s", static_cast<double>(largest) * 1e-6,
                    static_cast<double>(largest_at) * 1e-9);
      }
      if (s.out_of_order > 0) {
        std::printf(" out_of_order=%llu", static_cast<unsigned long long>(s.out_of_order));
      }
      std::printf("\n");
    }
  }
  const auto& sum = reader.summary();
  const auto& c = reader.counters();
  std::printf("summary: %s", !sum.footer_found ? "missing (no footer)"
                             : !sum.present    ? "none"
                             : sum.usable()    ? "present, CRC ok"
                                               : "present but unusable");
  if (sum.has_statistics) {
    std::printf(" (statistics: %llu messages, %u chunks)",
                static_cast<unsigned long long>(sum.message_count), sum.chunk_count);
  }
  std::printf(
      "\nchunks: decoded=%llu bad=%llu; unknown records skipped=%llu; bad records=%llu; "
      "messages without channel=%llu\n",
      static_cast<unsigned long long>(c.chunks), static_cast<unsigned long long>(c.chunks_bad),
      static_cast<unsigned long long>(c.unknown_records),
      static_cast<unsigned long long>(c.bad_records),
      static_cast<unsigned long long>(c.orphan_messages));
  std::printf("state: %s\n",
              reader.complete() ? "complete" : ("damaged: " + reader.stop_reason()).c_str());
  for (const auto& i : reader.issues()) {
    std::printf("error: offset %llu: %s\n", static_cast<unsigned long long>(i.offset),
                i.what.c_str());
  }
  if (c.issues > reader.issues().size()) {
    std::printf("error: ... and %llu more\n",
                static_cast<unsigned long long>(c.issues - reader.issues().size()));
  }
  return reader.complete() ? 0 : 1;
}

}  // namespace posed::posectl
