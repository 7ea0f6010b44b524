#include "drivers/recording/mcap_inspection.hpp"

#include <algorithm>
#include <charconv>
#include <map>

#include "drivers/recording/raw_channels.hpp"

namespace posed::drivers::recording {

namespace {

struct Accumulator {
  std::uint64_t messages = 0, bytes = 0, first = 0, last = 0, out_of_order = 0;
  std::vector<std::int64_t> intervals_ns;
  /// the longest intervals so far, as candidates for the largest gaps (shortest first)
  std::vector<McapGap> longest;
};

void keep_longest(std::vector<McapGap>& longest, const McapGap& gap, std::size_t n) {
  if (n == 0) return;
  if (longest.size() == n && gap.length_ns <= longest.front().length_ns) return;
  longest.insert(std::upper_bound(
                     longest.begin(), longest.end(), gap,
                     [](const McapGap& a, const McapGap& b) { return a.length_ns < b.length_ns; }),
                 gap);
  if (longest.size() > n) longest.erase(longest.begin());
}

void finish(McapReader& reader, const McapInspectOptions& options,
            std::map<std::uint16_t, Accumulator>& acc, McapInspection& out) {
  out.file_size_bytes = reader.file_size_bytes();
  out.profile = reader.profile();
  out.library = reader.library();
  out.summary = reader.summary();
  out.counters = reader.counters();
  out.complete = reader.complete();
  out.stop_reason = reader.stop_reason();
  out.issues = reader.issues();
  out.unknown_records = reader.unknown_records();
  for (const auto& record : reader.metadata()) {
    if (record.name != raw::kMetadataName) continue;
    const auto it = record.entries.find(std::string(raw::kHostToWallKey));
    std::int64_t ns = 0;
    if (it != record.entries.end() &&
        std::from_chars(it->second.data(), it->second.data() + it->second.size(), ns).ec ==
            std::errc{}) {
      out.host_to_wall = HostToWall{Duration::from_ns(ns)};
    }
  }
  bool any = false;
  for (const auto& [id, channel] : reader.channels()) {
    McapChannelStats s;
    s.channel = channel;
    if (channel.schema_id != 0) {
      const McapSchemaRecord* schema = reader.schema(channel.schema_id);
      s.schema_name = schema != nullptr ? schema->name : "MISSING";
    }
    if (const auto it = acc.find(id); it != acc.end()) {
      Accumulator& a = it->second;
      s.messages = a.messages;
      s.bytes = a.bytes;
      s.first_log_ns = a.first;
      s.last_log_ns = a.last;
      s.out_of_order = a.out_of_order;
      if (a.messages > 1 && a.last > a.first) {
        s.rate_hz = static_cast<double>(a.messages - 1) / s.span_s();
      }
      if (!a.intervals_ns.empty()) {
        std::vector<std::int64_t>& v = a.intervals_ns;
        const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
        std::nth_element(v.begin(), mid, v.end());
        s.median_interval_ns = *mid;
        const double limit = options.gap_factor * static_cast<double>(s.median_interval_ns);
        if (s.median_interval_ns > 0) {
          s.gaps = static_cast<std::uint64_t>(std::count_if(
              v.begin(), v.end(), [&](std::int64_t d) { return static_cast<double>(d) > limit; }));
          for (auto g = a.longest.rbegin(); g != a.longest.rend(); ++g) {
            if (static_cast<double>(g->length_ns) > limit) s.largest_gaps.push_back(*g);
          }
        }
      }
      if (a.messages > 0) {
        out.first_log_ns = any ? std::min(out.first_log_ns, a.first) : a.first;
        out.last_log_ns = any ? std::max(out.last_log_ns, a.last) : a.last;
        any = true;
      }
    }
    out.messages += s.messages;
    out.channels.push_back(std::move(s));
  }
}

bool scan(McapReader& reader, const McapInspectOptions& options, McapInspection& out) {
  out = {};
  std::map<std::uint16_t, Accumulator> acc;
  McapMessage m;
  std::uint64_t n = 0;
  while (reader.next(m)) {
    Accumulator& a = acc[m.channel->id];
    if (a.messages > 0) {
      const auto d = static_cast<std::int64_t>(m.log_time_ns - a.last);
      if (m.log_time_ns < a.last) ++a.out_of_order;
      a.intervals_ns.push_back(d);
      keep_longest(a.longest, {a.last, d, m.record_offset}, options.max_gaps);
    } else {
      a.first = m.log_time_ns;
    }
    a.last = m.log_time_ns;
    ++a.messages;
    a.bytes += m.data.size();
    if (options.progress && (++n & 0xFFFF) == 0) options.progress(reader.offset());
  }
  finish(reader, options, acc, out);
  return true;
}

}  // namespace

bool inspect_mcap(const std::string& path, const McapInspectOptions& options, McapInspection& out,
                  std::string& error) {
  McapReader reader;
  McapReaderOptions ro;
  ro.verify_crcs = options.verify_crcs;
  if (!reader.open(path, error, ro)) return false;
  return scan(reader, options, out);
}

bool inspect_mcap_bytes(std::span<const std::byte> bytes, const McapInspectOptions& options,
                        McapInspection& out, std::string& error) {
  McapReader reader;
  McapReaderOptions ro;
  ro.verify_crcs = options.verify_crcs;
  if (!reader.open_bytes(bytes, error, ro)) return false;
  return scan(reader, options, out);
}

}  // namespace posed::drivers::recording
