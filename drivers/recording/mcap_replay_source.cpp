#include "drivers/recording/mcap_replay_source.hpp"

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"
#include "drivers/recording/raw_channels.hpp"

namespace posed::drivers::recording {

namespace {}  // namespace

McapReplaySource::McapReplaySource(McapReplayConfig config)
    : config_(std::move(config)),
      name_(config_.name.empty() ? config_.stream : config_.name),
      loop_shift_ns_(config_.time_shift.ns) {}

bool McapReplaySource::wanted(const McapChannelRecord& c) const {
  return raw::is_stream_channel(c.message_encoding, c.metadata) &&
         raw::metadata_value(c.metadata, raw::kStreamKey) == config_.stream;
}

bool McapReplaySource::open(std::string& error) {
  if (opened_) return true;
  McapReaderOptions options;
  options.chunk_cache = config_.chunk_cache;
  if (!reader_.open(config_.path, error, options)) return false;
  if (reader_.summary().usable()) {
    std::set<std::string> streams;
    bool found = false;
    for (const auto& [id, c] : reader_.channels()) {
      if (raw::is_stream_channel(c.message_encoding, c.metadata)) {
        streams.insert(raw::metadata_value(c.metadata, raw::kStreamKey));
      }
      if (wanted(c)) {
        found = true;
        std::lock_guard lock(info_mutex_);
        channels_[id] = {
            raw::parse_source_channel(raw::metadata_value(c.metadata, raw::kSourceChannelKey)),
            c.topic, raw::metadata_value(c.metadata, raw::kWireFormatKey), c.metadata};
      }
    }
    if (!found) {
      std::string list;
      for (const auto& s : streams) list += (list.empty() ? "" : ", ") + s;
      error = "mcap " + config_.path + ": no raw channel of stream '" + config_.stream +
              "' (streams: " + (list.empty() ? "none" : list) + ")";
      return false;
    }
  }
  opened_ = true;
  return true;
}

void McapReplaySource::note_damage() {
  if (reader_.complete() && reader_.counters().issues == 0) return;
  std::string what = reader_.stop_reason();
  if (what.empty() && !reader_.issues().empty()) {
    const auto& i = reader_.issues().front();
    what = i.what + " at offset " + std::to_string(i.offset);
  }
  if (what.empty()) return;
  std::lock_guard lock(info_mutex_);
  if (!damage_.empty()) return;  // log once, not once per loop pass
  damage_ = what;
  POSED_LOG_WARN("replay %s (%s): recording damaged: %s", config_.path.c_str(), name_.c_str(),
                 what.c_str());
}

bool McapReplaySource::fetch() {
  // Ends one pass; true when looping goes on with the next.
  auto end_pass = [&]() {
    note_damage();
    if (!config_.loop || delivered_this_pass_ == 0 || stop_.load(std::memory_order_relaxed)) {
      return false;
    }
    const std::int64_t gap = std::max<std::int64_t>(1, last_log_ns_ - prev_log_ns_);
    loop_shift_ns_ += (last_log_ns_ - first_log_ns_ - config_.start_offset.ns) + gap;
    reader_.rewind();
    ++passes_;
    delivered_this_pass_ = 0;
    return true;
  };
  McapMessage m;
  for (;;) {
    if (!reader_.next(m)) {
      if (end_pass()) continue;
      return false;
    }
    if (!wanted(*m.channel)) continue;
    const auto id = m.channel->id;
    {
      std::lock_guard lock(info_mutex_);
      if (channels_.find(id) == channels_.end()) {
        channels_[id] = {raw::parse_source_channel(
                             raw::metadata_value(m.channel->metadata, raw::kSourceChannelKey)),
                         m.channel->topic,
                         raw::metadata_value(m.channel->metadata, raw::kWireFormatKey),
                         m.channel->metadata};
      }
    }
    const auto log = static_cast<std::int64_t>(m.log_time_ns);
    if (!have_first_) {
      have_first_ = true;
      first_log_ns_ = log;
    }
    const std::int64_t begin = first_log_ns_ + config_.start_offset.ns;
    if (log < begin) continue;
    if (config_.duration.ns > 0 && log > begin + config_.duration.ns) {
      if (end_pass()) continue;
      return false;
    }
    prev_log_ns_ = delivered_this_pass_ > 0 ? last_log_ns_ : log;
    if (delivered_this_pass_ == 0) pass_first_log_ns_ = log;
    last_log_ns_ = log;
    ++delivered_this_pass_;
    pending_ = m;
    pending_log_ns_ = log + loop_shift_ns_;
    have_pending_ = true;
    return true;
  }
}

ReadStatus McapReplaySource::read(RawChunk& chunk, Duration timeout) {
  if (!opened_ || stop_.load(std::memory_order_relaxed)) return ReadStatus::kEndOfStream;
  if (!have_pending_) {
    if (ended_ || !fetch()) {
      ended_ = true;
      return ReadStatus::kEndOfStream;
    }
  }
  // When the pending message is due on the host clock (recorded timing, scaled by the rate, or
  // one shift shared by every stream with live stamps); none at full speed.
  std::int64_t receive_ns = pending_log_ns_;
  std::optional<HostTime> due;
  if (config_.live_timeline) {
    receive_ns += config_.live_timeline->shift(pending_log_ns_, host_now()).ns;
    due = HostTime::from_ns(receive_ns);
  } else if (config_.rate > 0) {
    if (!paced_) {
      paced_ = true;
      anchor_host_ = host_now();
      anchor_log_ns_ = pending_log_ns_;
    }
    const auto offset_ns = static_cast<std::int64_t>(
        static_cast<double>(pending_log_ns_ - anchor_log_ns_) / config_.rate);
    due = anchor_host_ + Duration::from_ns(offset_ns);
  }
  if (due && *due > host_now()) {
    const Duration wait = std::min(*due - host_now(), timeout);
    std::unique_lock lock(wait_mutex_);
    wait_cv_.wait_for(lock, std::chrono::nanoseconds(std::max<std::int64_t>(0, wait.ns)),
                      [&] { return stop_.load(std::memory_order_relaxed); });
    if (stop_.load(std::memory_order_relaxed)) return ReadStatus::kEndOfStream;
    if (host_now() < *due) return ReadStatus::kTimeout;
  }
  chunk.bytes = pending_.data;
  chunk.host_receive = HostTime::from_ns(receive_ns);
  {
    std::lock_guard lock(info_mutex_);
    chunk.channel = channels_[pending_.channel->id].source_channel;
  }
  have_pending_ = false;
  counts_.count_chunk(chunk.bytes.size());
  return ReadStatus::kData;
}

void McapReplaySource::request_stop() {
  stop_.store(true, std::memory_order_relaxed);
  std::lock_guard lock(wait_mutex_);
  wait_cv_.notify_all();
}

McapReplaySource::DeliveredSpan McapReplaySource::delivered_span() const {
  DeliveredSpan span;
  span.messages = delivered_this_pass_;
  if (span.messages == 0) return span;
  span.first_log_ns = pass_first_log_ns_;
  span.last_log_ns = last_log_ns_;
  span.last_gap_ns = span.messages > 1 ? last_log_ns_ - prev_log_ns_ : 0;
  return span;
}

SourceCounters McapReplaySource::counters() const { return counts_.snapshot(); }

std::string_view McapReplaySource::wire_format(std::uint32_t channel) const {
  std::lock_guard lock(info_mutex_);
  // std::map nodes never move and channels are never erased, so the view outlives the lock.
  for (const auto& [id, c] : channels_) {
    if (c.source_channel == channel) return c.wire_format;
  }
  return {};
}

std::vector<ReplayChannel> McapReplaySource::channels() const {
  std::lock_guard lock(info_mutex_);
  std::vector<ReplayChannel> out;
  for (const auto& [id, c] : channels_) out.push_back(c);
  return out;
}

std::string McapReplaySource::damage() const {
  std::lock_guard lock(info_mutex_);
  return damage_;
}

}  // namespace posed::drivers::recording
