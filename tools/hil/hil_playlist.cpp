#include "tools/hil/hil_playlist.hpp"

#include <algorithm>
#include <charconv>
#include <set>

#include "drivers/common/wire_format.hpp"
#include "drivers/recording/raw_channels.hpp"

namespace posed::hil {

namespace raw = drivers::recording::raw;

namespace {}  // namespace

std::string_view to_string(HilOutput output) {
  switch (output) {
    case HilOutput::kNone:
      return "none";
    case HilOutput::kUdpData:
      return "udp data";
    case HilOutput::kUdpPosition:
      return "udp position";
    case HilOutput::kSerial:
      return "pty";
    case HilOutput::kIio:
      return "iio";
  }
  return "none";
}

HilOutput output_for_wire_format(std::string_view wire_format) {
  if (wire_format == drivers::wire::kVelodyneData) return HilOutput::kUdpData;
  if (wire_format == drivers::wire::kVelodynePosition) return HilOutput::kUdpPosition;
  if (wire_format == drivers::wire::kA9Serial) return HilOutput::kSerial;
  if (wire_format.starts_with(drivers::wire::kIioAccel3d) ||
      wire_format.starts_with(drivers::wire::kIioGyro3d)) {
    return HilOutput::kIio;
  }
  return HilOutput::kNone;
}

bool HilPlaylist::open(const HilPlaylistOptions& options, std::string& error) {
  options_ = options;
  if (!reader_.open(options_.path, error)) return false;
  // The channel list comes from the summary; a file cut short has none, so scan it once.
  if (!reader_.summary().usable()) {
    drivers::recording::McapMessage m;
    while (reader_.next(m)) {
    }
    reader_.rewind();
  }
  std::set<std::string> formats;
  for (const auto& [id, c] : reader_.channels()) {
    if (c.message_encoding != raw::kMessageEncoding) continue;
    HilChannel h;
    h.id = id;
    h.topic = c.topic;
    h.stream = raw::metadata_value(c.metadata, raw::kStreamKey);
    h.wire_format = raw::metadata_value(c.metadata, raw::kWireFormatKey);
    h.source_channel =
        raw::parse_source_channel(raw::metadata_value(c.metadata, raw::kSourceChannelKey));
    h.output = output_for_wire_format(h.wire_format);
    switch (h.output) {
      case HilOutput::kSerial:
        h.sent = options_.serial;
        break;
      case HilOutput::kIio:
        h.sent = options_.iio;
        break;
      case HilOutput::kUdpData:
      case HilOutput::kUdpPosition:
        h.sent = options_.udp;
        break;
      case HilOutput::kNone:
        h.sent = false;
        break;
    }
    if (channel_index_.size() <= id) channel_index_.resize(id + 1u, -1);
    channel_index_[id] = static_cast<std::int64_t>(channels_.size());
    formats.insert(h.wire_format);
    channels_.push_back(std::move(h));
  }
  if (std::none_of(channels_.begin(), channels_.end(), [](const auto& c) { return c.sent; })) {
    std::string list;
    for (const auto& f : formats) list += (list.empty() ? "" : ", ") + f;
    error = "mcap " + options_.path + ": no raw channel to re-emit (raw wire formats: " +
            (list.empty() ? std::string("none") : list) +
            "; sent are velodyne-udp-data/-position over UDP, a9-serial on a pty and, with --iio, "
            "the D435i's IMU as IIO devices)";
    return false;
  }
  return true;
}

std::int64_t HilPlaylist::end_log_ns() const {
  const auto& s = reader_.summary();
  if (!s.usable() || !s.has_statistics) return 0;
  auto end = static_cast<std::int64_t>(s.message_end_time_ns);
  if (options_.duration.ns > 0 && have_first_) {
    end = std::min(end, begin_log_ns_ + options_.duration.ns);
  }
  return end;
}

bool HilPlaylist::recorded_host_to_wall(HostToWall& out) const {
  for (const auto& record : reader_.metadata()) {
    if (record.name != raw::kMetadataName) continue;
    const auto it = record.entries.find(std::string(raw::kHostToWallKey));
    if (it == record.entries.end()) continue;
    std::int64_t ns = 0;
    const auto [end, ec] =
        std::from_chars(it->second.data(), it->second.data() + it->second.size(), ns);
    if (ec != std::errc{}) continue;
    out = HostToWall{Duration::from_ns(ns)};
    return true;
  }
  return false;
}

void HilPlaylist::note_damage() {
  if (!damage_.empty() || (reader_.complete() && reader_.counters().issues == 0)) return;
  damage_ = reader_.stop_reason();
  if (damage_.empty() && !reader_.issues().empty()) {
    const auto& i = reader_.issues().front();
    damage_ = i.what + " at offset " + std::to_string(i.offset);
  }
}

bool HilPlaylist::end_pass() {
  note_damage();
  if (!options_.loop || sent_this_pass_ == 0) return false;
  const std::int64_t gap = std::max<std::int64_t>(1'000, last_gap_ns_);
  shift_ns_ += (last_log_ns_ - begin_log_ns_) + gap;
  reader_.rewind();
  ++passes_;
  sent_this_pass_ = 0;
  return true;
}

bool HilPlaylist::read_one() {
  drivers::recording::McapMessage m;
  for (;;) {
    if (!reader_.next(m)) {
      if (end_pass()) continue;
      return false;
    }
    const std::uint16_t id = m.channel->id;
    if (id >= channel_index_.size() || channel_index_[id] < 0) continue;
    const auto index = static_cast<std::size_t>(channel_index_[id]);
    if (!channels_[index].sent) continue;
    const auto log = static_cast<std::int64_t>(m.log_time_ns);
    if (!have_first_) {
      have_first_ = true;
      first_log_ns_ = log;
      begin_log_ns_ = first_log_ns_ + options_.start.ns;
    }
    if (options_.start.ns > 0 && log < begin_log_ns_) continue;
    if (options_.duration.ns > 0 && log > begin_log_ns_ + options_.duration.ns) {
      if (end_pass()) continue;
      return false;
    }
    if (sent_this_pass_ == 0) {
      last_log_ns_ = log;
      last_gap_ns_ = 0;
    } else if (log > last_log_ns_) {
      last_gap_ns_ = log - last_log_ns_;
      last_log_ns_ = log;
    }
    ++sent_this_pass_;
    Pending p;
    p.log_ns = log + shift_ns_;
    p.order = order_++;
    p.message.log_ns = p.log_ns;
    p.message.output = channels_[index].output;
    p.message.channel = index;
    p.message.bytes.assign(m.data.begin(), m.data.end());
    newest_in_heap_ns_ = std::max(newest_in_heap_ns_, p.log_ns);
    heap_.push(std::move(p));
    return true;
  }
}

bool HilPlaylist::next(HilMessage& out) {
  // Fill until the oldest pending message is a whole window older than the newest read: nothing
  // still in the file can then come before it.
  while (!file_done_ &&
         (heap_.empty() || newest_in_heap_ns_ - heap_.top().log_ns < options_.reorder_window.ns)) {
    if (!read_one()) file_done_ = true;
  }
  if (heap_.empty()) return false;
  // priority_queue::top() is const; the message is moved out just before pop() discards it.
  out = std::move(const_cast<Pending&>(heap_.top()).message);
  heap_.pop();
  return true;
}

}  // namespace posed::hil
