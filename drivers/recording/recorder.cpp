#include "drivers/recording/recorder.hpp"

#include <algorithm>
#include <chrono>

#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "drivers/recording/ros2_messages.hpp"

namespace posed::drivers::recording {

Recorder::Recorder() = default;

Recorder::~Recorder() { close(); }

std::string Recorder::file_name(std::uint64_t index) const {
  if (index == 0) return base_path_;
  // run.mcap -> run_001.mcap, run_002.mcap, ...
  const auto dot = base_path_.rfind('.');
  const auto slash = base_path_.rfind('/');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  char num[32];
  std::snprintf(num, sizeof num, "_%03llu", static_cast<unsigned long long>(index));
  return has_ext ? base_path_.substr(0, dot) + num + base_path_.substr(dot) : base_path_ + num;
}

bool Recorder::open(const std::string& path, const RecorderOptions& options, std::string& error) {
  if (open_) {
    error = "recorder: already open on " + base_path_;
    return false;
  }
  options_ = options;
  if (options_.host_to_wall.wall_minus_host.ns == 0) {
    options_.host_to_wall.wall_minus_host = Duration::from_ns(wall_now().ns - host_now().ns);
  }
  base_path_ = path;
  file_index_ = 0;
  if (!open_file(error)) return false;
  open_ = true;
  running_.store(true, std::memory_order_release);
  thread_ = std::thread([this] { run(); });
  return true;
}

bool Recorder::open_file(std::string& error) {
  const std::string name = file_name(file_index_);
  if (!writer_.open(name, options_.writer, error)) return false;
  {
    std::lock_guard lock(mutex_);
    files_.push_back(name);
  }
  registered_in_file_ = 0;
  file_has_messages_ = false;
  schema_ids_.clear();
  writer_.write_metadata(
      raw::kMetadataName,
      {{std::string(raw::kHostToWallKey), std::to_string(options_.host_to_wall.wall_minus_host.ns)},
       {"file_index", std::to_string(file_index_)},
       {"log_time_clock", "host CLOCK_MONOTONIC [ns]"}});
  for (const auto& [record, entries] : options_.metadata) writer_.write_metadata(record, entries);
  register_channels();
  return true;
}

void Recorder::register_channels() {
  const std::size_t n = channel_count_.load(std::memory_order_acquire);
  for (; registered_in_file_ < n; ++registered_in_file_) {
    const Channel& c = *channels_[registered_in_file_];
    std::uint16_t schema = 0;
    std::string_view encoding = raw::kMessageEncoding;
    if (!c.schema_name.empty()) {
      auto it = schema_ids_.find(c.schema_name);
      if (it == schema_ids_.end()) {
        const std::string_view s = ros2::schema_for(c.schema_name);
        it = schema_ids_
                 .emplace(
                     c.schema_name,
                     writer_.add_schema(c.schema_name, ros2::kSchemaEncoding,
                                        {reinterpret_cast<const std::byte*>(s.data()), s.size()}))
                 .first;
      }
      schema = it->second;
      encoding = ros2::kMessageEncoding;
    }
    // Channel ids are the Recorder's indices in every file, so they match across rotations.
    writer_.add_channel(c.topic, encoding, schema, c.metadata);
  }
}

std::uint16_t Recorder::add_channel(Kind kind, std::string topic,
                                    std::map<std::string, std::string> metadata,
                                    std::string schema_name, std::size_t queue_capacity) {
  // Called with mutex_ held.
  const std::size_t n = channel_count_.load(std::memory_order_relaxed);
  if (n >= kMaxChannels) return kInvalidChannel;
  auto c = std::make_unique<Channel>(queue_capacity > 0 ? queue_capacity : options_.queue_capacity);
  c->kind = kind;
  c->topic = std::move(topic);
  c->metadata = std::move(metadata);
  c->schema_name = std::move(schema_name);
  channels_[n] = std::move(c);
  channel_count_.store(n + 1, std::memory_order_release);
  return static_cast<std::uint16_t>(n);
}

std::uint16_t Recorder::add_raw_channel(std::string_view stream, std::string_view wire_format,
                                        const std::map<std::string, std::string>& metadata,
                                        std::uint32_t source_channel) {
  std::map<std::string, std::string> md = metadata;
  md[std::string(raw::kStreamKey)] = stream;
  md[std::string(raw::kWireFormatKey)] = wire_format;
  md[std::string(raw::kSourceChannelKey)] = std::to_string(source_channel);
  std::string topic = raw::topic(stream, source_channel);
  std::lock_guard lock(mutex_);
  // The same channel again (a `posed --replay --loop` pass after the first taps fresh Sources):
  // its messages go on in the channel it already has.
  const std::size_t n = channel_count_.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < n; ++i) {
    const Channel& c = *channels_[i];
    if (c.kind == Kind::kRaw && c.topic == topic && c.metadata == md) {
      return static_cast<std::uint16_t>(i);
    }
  }
  return add_channel(Kind::kRaw, std::move(topic), std::move(md));
}

std::uint16_t Recorder::pose_channel(std::string_view topic, Kind kind) {
  std::lock_guard lock(mutex_);
  if (const auto it = pose_topics_.find(topic); it != pose_topics_.end()) return it->second;
  const std::string_view type = kind == Kind::kPose ? ros2::kPoseStampedName : ros2::kOdometryName;
  const auto id = add_channel(kind, std::string(topic), {}, std::string(type));
  if (id != kInvalidChannel) pose_topics_.emplace(std::string(topic), id);
  return id;
}

std::uint16_t Recorder::add_ros2_channel(std::string_view topic, std::string_view type_name,
                                         std::size_t queue_capacity) {
  if (ros2::schema_for(type_name).empty()) return kInvalidChannel;
  std::lock_guard lock(mutex_);
  return add_channel(Kind::kRos2, std::string(topic), {}, std::string(type_name), queue_capacity);
}

bool Recorder::write_ros2(std::uint16_t channel, WallTime stamp, std::span<const std::byte> cdr) {
  if (channel >= channel_count_.load(std::memory_order_acquire) ||
      channels_[channel]->kind != Kind::kRos2) {
    return false;
  }
  return push(channel, options_.host_to_wall.to_host(stamp).ns,
              std::vector<std::byte>(cdr.begin(), cdr.end()));
}

bool Recorder::push(std::uint16_t id, std::int64_t log_time_ns, std::vector<std::byte> bytes) {
  if (!open_ || id >= channel_count_.load(std::memory_order_acquire)) return false;
  Channel& c = *channels_[id];
  const std::size_t size = bytes.size();
  const std::uint64_t order = push_order_.fetch_add(1, std::memory_order_relaxed);
  const PushResult r = c.queue.push(Item{log_time_ns, order, std::move(bytes)});
  if (r != PushResult::kPushed) return false;
  if (options_.in_push_order) pushed_before_.store(order + 1, std::memory_order_release);
  c.bytes.store(c.bytes.load(std::memory_order_relaxed) + size, std::memory_order_relaxed);
  return true;
}

bool Recorder::record(std::uint16_t channel, const RawChunk& chunk) {
  return push(channel, chunk.host_receive.ns,
              std::vector<std::byte>(chunk.bytes.begin(), chunk.bytes.end()));
}

bool Recorder::write_pose(std::string_view topic, WallTime stamp, std::string_view frame,
                          const std::array<double, 3>& p_m, const std::array<double, 4>& q_xyzw) {
  const auto id = pose_channel(topic, Kind::kPose);
  if (id == kInvalidChannel || channels_[id]->kind != Kind::kPose) return false;
  ros2::StampedPose pose{stamp, std::string(frame), p_m, q_xyzw};
  std::vector<std::byte> cdr;
  ros2::encode_pose_stamped(pose, cdr);
  return push(id, options_.host_to_wall.to_host(stamp).ns, std::move(cdr));
}

bool Recorder::write_odometry(std::string_view topic, WallTime stamp, std::string_view frame,
                              std::string_view child_frame, const std::array<double, 3>& p_m,
                              const std::array<double, 4>& q_xyzw,
                              const std::array<double, 3>& v_mps,
                              const std::array<double, 3>& w_radps) {
  const auto id = pose_channel(topic, Kind::kOdometry);
  if (id == kInvalidChannel || channels_[id]->kind != Kind::kOdometry) return false;
  ros2::StampedPose pose{stamp, std::string(frame), p_m, q_xyzw};
  std::vector<std::byte> cdr;
  ros2::encode_odometry(pose, child_frame, v_mps, w_radps, cdr);
  return push(id, options_.host_to_wall.to_host(stamp).ns, std::move(cdr));
}

void Recorder::rotate() {
  if (!writer_.close()) {
    std::lock_guard lock(mutex_);
    if (error_.empty()) error_ = writer_.error();
  }
  closed_bytes_.fetch_add(writer_.file_size_bytes(), std::memory_order_relaxed);
  ++file_index_;
  std::string error;
  if (!open_file(error)) {
    std::lock_guard lock(mutex_);
    if (error_.empty()) error_ = error;
    POSED_LOG_ERROR("recorder: %s", error.c_str());
  }
}

void Recorder::run() {
  struct Pending {
    std::int64_t log_time_ns;
    std::uint64_t order;
    std::uint16_t channel;
    std::vector<std::byte> bytes;
  };
  std::vector<Pending> batch;
  // in_push_order: items a pass took that were pushed after it began, for the next pass
  std::vector<Pending> held;
  HostTime last_flush = host_now();
  for (;;) {
    // Before draining: everything pushed before this is in the queues (one producer).
    const std::uint64_t pushed_before = pushed_before_.load(std::memory_order_acquire);
    // Read the flag before draining: whatever was queued before stop is drained below.
    const bool stopping = !running_.load(std::memory_order_acquire);
    // Drain only channels whose record is in the file: one added since register_channels() read
    // the count waits for the next pass, so no message precedes its channel record.
    std::size_t n = channel_count_.load(std::memory_order_acquire);
    if (writer_.is_open()) {
      register_channels();
      n = registered_in_file_;
    }
    batch.clear();
    if (options_.in_push_order) {
      // What an earlier pass took early, then every queue to the end: the pass writes exactly
      // the items pushed before it began, whatever the producer did meanwhile.
      std::vector<Pending> later;
      for (Pending& p : held) {
        (p.order < pushed_before ? batch : later).push_back(std::move(p));
      }
      held.swap(later);
      for (std::size_t i = 0; i < n; ++i) {
        Item item;
        while (channels_[i]->queue.try_pop(item)) {
          Pending p{item.log_time_ns, item.order, static_cast<std::uint16_t>(i),
                    std::move(item.bytes)};
          (p.order < pushed_before ? batch : held).push_back(std::move(p));
        }
      }
      std::sort(batch.begin(), batch.end(),
                [](const Pending& a, const Pending& b) { return a.order < b.order; });
    } else {
      for (std::size_t i = 0; i < n; ++i) {
        Item item;
        // Bounded per pass so one busy channel cannot starve the merge order of the others.
        for (int k = 0; k < 4096 && channels_[i]->queue.try_pop(item); ++k) {
          batch.push_back(
              {item.log_time_ns, item.order, static_cast<std::uint16_t>(i), std::move(item.bytes)});
        }
      }
      // Queues are drained in batches; ordering each batch by log time keeps the file close to
      // time order across channels (MCAP does not require it; players prefer it). Equal log
      // times keep the order they were pushed in: a Source's chunks of one read (a D435i frame's
      // metadata, then the frame) must replay in that order whatever channel each went to.
      std::sort(batch.begin(), batch.end(), [](const Pending& a, const Pending& b) {
        return a.log_time_ns != b.log_time_ns ? a.log_time_ns < b.log_time_ns : a.order < b.order;
      });
    }
    for (auto& p : batch) {
      if (!writer_.is_open()) {
        write_errors_.fetch_add(1, std::memory_order_relaxed);
        continue;
      }
      if (file_has_messages_ &&
          ((options_.rotate_bytes > 0 &&
            writer_.file_size_bytes() + writer_.pending_chunk_bytes() >= options_.rotate_bytes) ||
           (options_.rotate_after.ns > 0 &&
            p.log_time_ns - file_first_log_ns_ >= options_.rotate_after.ns))) {
        rotate();
        if (!writer_.is_open()) {
          write_errors_.fetch_add(1, std::memory_order_relaxed);
          continue;
        }
      }
      if (!file_has_messages_) {
        file_has_messages_ = true;
        file_first_log_ns_ = p.log_time_ns;
      }
      Channel& c = *channels_[p.channel];
      const auto t = static_cast<std::uint64_t>(p.log_time_ns);
      if (writer_.write_message(p.channel, c.sequence++, t, t, p.bytes)) {
        written_.fetch_add(1, std::memory_order_relaxed);
      } else {
        write_errors_.fetch_add(1, std::memory_order_relaxed);
      }
    }
    current_bytes_.store(writer_.file_size_bytes(), std::memory_order_relaxed);
    const HostTime now = host_now();
    if (options_.flush_interval.ns > 0 && now - last_flush >= options_.flush_interval) {
      writer_.flush_chunk();
      last_flush = now;
    }
    if (batch.empty()) {
      if (stopping && held.empty()) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  if (!writer_.error().empty()) {
    std::lock_guard lock(mutex_);
    if (error_.empty()) error_ = writer_.error();
  }
}

bool Recorder::close() {
  if (!open_) return error().empty();
  running_.store(false, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  if (!writer_.close()) {
    std::lock_guard lock(mutex_);
    if (error_.empty()) error_ = writer_.error();
  }
  closed_bytes_.fetch_add(writer_.file_size_bytes(), std::memory_order_relaxed);
  current_bytes_.store(0, std::memory_order_relaxed);
  open_ = false;
  return error().empty();
}

RecorderCounters Recorder::counters() const {
  RecorderCounters out;
  out.messages_written = written_.load(std::memory_order_relaxed);
  out.write_errors = write_errors_.load(std::memory_order_relaxed);
  out.bytes_on_disk = closed_bytes_.load(std::memory_order_relaxed) +
                      current_bytes_.load(std::memory_order_relaxed);
  const std::size_t n = channel_count_.load(std::memory_order_acquire);
  for (std::size_t i = 0; i < n; ++i) {
    const Channel& c = *channels_[i];
    const QueueCounters q = c.queue.counters();
    RecorderChannelCounters cc;
    cc.topic = c.topic;
    cc.recorded = q.pushed;
    cc.dropped = q.dropped();
    cc.bytes = c.bytes.load(std::memory_order_relaxed);
    out.dropped += cc.dropped;
    out.channels.push_back(std::move(cc));
  }
  std::lock_guard lock(mutex_);
  out.files = files_.size();
  return out;
}

std::vector<std::string> Recorder::files() const {
  std::lock_guard lock(mutex_);
  return files_;
}

std::string Recorder::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

}  // namespace posed::drivers::recording
