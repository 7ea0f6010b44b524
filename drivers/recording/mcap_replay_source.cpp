#include "drivers/recording/mcap_replay_source.hpp"

#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"
#include "drivers/recording/raw_channels.hpp"

namespace posed::drivers::recording {

namespace {

/// The calling thread at normal priority on every CPU, whatever the thread that started it ran
/// at (a new thread inherits its creator's policy and affinity): reading ahead must never take a
/// core from a real-time stage, nor wait for one pinned elsewhere.
void run_as_background_thread(const std::string& name) {
  sched_param normal{};
  normal.sched_priority = 0;
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal);
  cpu_set_t all;
  CPU_ZERO(&all);
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  for (long cpu = 0; cpu < cpus && cpu < CPU_SETSIZE; ++cpu) CPU_SET(static_cast<int>(cpu), &all);
  pthread_setaffinity_np(pthread_self(), sizeof all, &all);
  pthread_setname_np(pthread_self(), name.substr(0, 15).c_str());
}

/// A raw channel as the Source lists it, from its Channel record.
ReplayChannel replay_channel(const McapChannelRecord& c) {
  return {raw::parse_source_channel(raw::metadata_value(c.metadata, raw::kSourceChannelKey)),
          c.topic, raw::metadata_value(c.metadata, raw::kWireFormatKey), c.metadata};
}

}  // namespace

McapReplaySource::McapReplaySource(McapReplayConfig config)
    : config_(std::move(config)),
      name_(config_.name.empty() ? config_.stream : config_.name),
      loop_shift_ns_(config_.time_shift.ns) {}

McapReplaySource::~McapReplaySource() {
  request_stop();
  if (reader_thread_.joinable()) reader_thread_.join();
}

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
        channels_[id] = replay_channel(c);
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
  if (config_.read_ahead.ns > 0) {
    ahead_ = std::make_unique<SpscQueue<AheadMessage>>(kReadAheadMessages, DropPolicy::kDropNewest);
    spare_bytes_ =
        std::make_unique<SpscQueue<std::vector<std::byte>>>(kSpareBuffers, DropPolicy::kDropNewest);
    reader_thread_ = std::thread([this] { read_ahead_loop(); });
  }
  return true;
}

// The two threads wake each other only when the other waits, and the reader waits for half the
// window at a time: a replay of 1500 lidar packets a second then costs its reader a dozen wake-ups
// a second, not one per packet, and read() a system call only when it found nothing to take.
// Each side announces its wait (an atomic), then checks again before sleeping; the other side
// checks the announcement after its own store. Every one of these operations is sequentially
// consistent, so of the two store-then-load pairs one always sees the other (Dekker's pattern):
// no wake-up is lost or left over. (Not fences: ThreadSanitizer does not model them.)

void McapReplaySource::read_ahead_loop() {
  run_as_background_thread("posed-rd-" + name_);
  const std::int64_t window_ns = config_.read_ahead.ns;
  bool first = true;
  while (!stop_.load(std::memory_order_relaxed) && fetch()) {
    AheadMessage m;
    if (pending_.data.size() >= kRecycledBytes && spare_bytes_->try_pop(m.bytes)) {
      ahead_reused_.fetch_add(1, std::memory_order_relaxed);
    }
    m.bytes.assign(pending_.data.begin(), pending_.data.end());
    m.source_channel = pending_source_channel_;
    m.log_ns = pending_log_ns_;
    have_pending_ = false;
    if (first) {
      // Until read() takes one, the window starts at the first message.
      ahead_base_log_ns_.store(m.log_ns, std::memory_order_seq_cst);
      first = false;
    }
    // Room: under the message cap, and within the window of the newest message read() took.
    while (!stop_.load(std::memory_order_relaxed)) {
      const bool under_cap = ahead_->size() < ahead_->capacity();
      if (under_cap && m.log_ns - ahead_base_log_ns_.load() <= window_ns) break;
      // Wait for read() to take half the window (a full queue is polled every 20 ms).
      const std::int64_t wake_at = m.log_ns - window_ns / 2;
      ahead_wake_reader_at_ns_.store(wake_at);
      bool woken = false;
      if (!under_cap || ahead_base_log_ns_.load() < wake_at) {
        woken = ahead_room_.try_acquire_for(std::chrono::milliseconds(20));
      }
      // read() took the announcement, so its release is on the way, if not consumed: consume it.
      if (ahead_wake_reader_at_ns_.exchange(kNoWake) == kNoWake && !woken) ahead_room_.acquire();
    }
    if (stop_.load(std::memory_order_relaxed)) break;
    ahead_->push(std::move(m));
    ahead_pushed_.fetch_add(1);
    if (ahead_consumer_waiting_.exchange(false)) ahead_filled_.release();
  }
  ahead_ended_.store(true);
  if (ahead_consumer_waiting_.exchange(false)) ahead_filled_.release();
}

bool McapReplaySource::take_ahead(Duration timeout) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::nanoseconds(timeout.ns);
  for (;;) {
    // Read before the pop: ended and then empty means nothing more will come.
    const bool ended = ahead_ended_.load();
    // The last message's bytes are done with (read() handed them out until this call).
    if (current_.bytes.capacity() >= kRecycledBytes) spare_bytes_->push(std::move(current_.bytes));
    if (ahead_->try_pop(current_)) {
      ++ahead_taken_;
      ahead_base_log_ns_.store(current_.log_ns);
      std::int64_t wake_at = ahead_wake_reader_at_ns_.load();
      if (wake_at != kNoWake && current_.log_ns >= wake_at &&
          ahead_wake_reader_at_ns_.compare_exchange_strong(wake_at, kNoWake)) {
        ahead_room_.release();
      }
      have_current_ = true;
      return true;
    }
    if (ended) {
      ended_ = true;
      return false;
    }
    if (stop_.load(std::memory_order_relaxed)) return false;
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= std::chrono::nanoseconds(0)) return false;
    ahead_consumer_waiting_.store(true);
    bool woken = false;
    if (ahead_pushed_.load() == ahead_taken_ && !ahead_ended_.load()) {
      woken = ahead_filled_.try_acquire_for(left);
    }
    // The reader took the announcement, so its release is on the way, if not consumed: consume it.
    if (!ahead_consumer_waiting_.exchange(false) && !woken) ahead_filled_.acquire();
  }
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
    passes_.fetch_add(1, std::memory_order_relaxed);
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
      // The channel's record, made the first time it is seen; its source channel goes with the
      // message, so delivering it needs no second look.
      std::lock_guard lock(info_mutex_);
      auto it = channels_.find(id);
      if (it == channels_.end()) it = channels_.emplace(id, replay_channel(*m.channel)).first;
      pending_source_channel_ = it->second.source_channel;
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
  std::int64_t log_ns = 0;
  if (ahead_) {
    if (!have_current_ && (ended_ || !take_ahead(timeout))) {
      return ended_ || stop_.load(std::memory_order_relaxed) ? ReadStatus::kEndOfStream
                                                             : ReadStatus::kTimeout;
    }
    log_ns = current_.log_ns;
  } else {
    if (!have_pending_) {
      if (ended_ || !fetch()) {
        ended_ = true;
        return ReadStatus::kEndOfStream;
      }
    }
    log_ns = pending_log_ns_;
  }
  // When the message is due on the host clock (recorded timing, scaled by the rate, or one shift
  // shared by every stream with live stamps); none at full speed.
  std::int64_t receive_ns = log_ns;
  std::optional<HostTime> due;
  if (config_.live_timeline) {
    receive_ns += config_.live_timeline->shift(log_ns, host_now()).ns;
    due = HostTime::from_ns(receive_ns);
  } else if (config_.rate > 0) {
    if (!paced_) {
      paced_ = true;
      anchor_host_ = host_now();
      anchor_log_ns_ = log_ns;
    }
    const auto offset_ns =
        static_cast<std::int64_t>(static_cast<double>(log_ns - anchor_log_ns_) / config_.rate);
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
  chunk.host_receive = HostTime::from_ns(receive_ns);
  if (ahead_) {
    // No lock here: the reader thread holds info_mutex_ at normal priority.
    chunk.bytes = current_.bytes;
    chunk.channel = current_.source_channel;
    have_current_ = false;
  } else {
    chunk.bytes = pending_.data;
    chunk.channel = pending_source_channel_;
    have_pending_ = false;
  }
  counts_.count_chunk(chunk.bytes.size());
  return ReadStatus::kData;
}

void McapReplaySource::request_stop() {
  stop_.store(true, std::memory_order_relaxed);
  ahead_room_.release();
  ahead_filled_.release();
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
