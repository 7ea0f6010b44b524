#pragma once
// Replays one stream of an MCAP recording through the Source interface (DESIGN.md, Data flow):
// every raw channel whose posed.stream matches (raw_channels.hpp; imported ROS 1 channels mapped
// onto the stream count as raw channels whose wire format is "ros1:<type>"), merged in file
// order, each
// read() returning the recorded bytes with the recorded log time as host_receive and the
// recorded posed.source_channel as RawChunk::channel. Decoders, ClockSync and fusion downstream
// cannot tell it from the device, and, being not live, the pipeline never drops its data:
// the same file gives the same poses every time.
//
// A recording cut short replays up to the damage, then ends; the damage is logged once and kept
// in damage().
//
// Paced replays can read ahead (McapReplayConfig::read_ahead): a thread of its own, at normal
// priority, reads, decompresses and CRC-checks the file up to that much log time ahead of what
// was delivered, so read() only waits for the message to be due and hands it over. On the robot
// the IMU's thread does nothing but read its serial port and publish odometry; without this, a
// replay's IMU thread also decompressed other streams' chunks and folded the file's CRC, 4-7 ms
// at a time, and that showed as odometry latency that no robot has (docs/realtime.md).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <semaphore>
#include <string>
#include <thread>
#include <vector>

#include "core/spsc_queue.hpp"
#include "drivers/common/source.hpp"
#include "drivers/recording/mcap_reader.hpp"

namespace posed::drivers::recording {

/// One time base for the Sources of one replay (`posed --replay --live-stamps`): the first
/// message any of them delivers fixes the shift from the recording's log time to the host clock
/// now; every stream is then paced at recorded timing against it and stamped with log time +
/// shift as its receive time, so the replay looks live to everything downstream (ClockSync, the
/// estimator, DDS subscribers measuring latency) with the streams as far apart as recorded.
class ReplayTimeline {
 public:
  /// host receive = log time + shift(); the first call fixes it from `log_ns` and `host`.
  Duration shift(std::int64_t log_ns, HostTime host) {
    std::lock_guard lock(mutex_);
    if (!set_) {
      shift_ = Duration::from_ns(host.ns - log_ns);
      set_ = true;
    }
    return shift_;
  }

 private:
  std::mutex mutex_;
  bool set_ = false;
  Duration shift_;
};

struct McapReplayConfig {
  /// the recording
  std::string path;
  /// posed.stream of the raw channels to replay ("imu", "lidar")
  std::string stream;
  /// Source name for logs and status; empty = `stream`
  std::string name;
  /// 1 = original timing, N = N times faster, 0 = as fast as read() is called (no sleeping)
  double rate = 1.0;
  /// skip this much log time from the stream's first message
  Duration start_offset = Duration::from_ns(0);
  /// replay this much log time after the start; 0 = to the end
  Duration duration = Duration::from_ns(0);
  /// start again at the end; host_receive keeps increasing (each pass is shifted by the span
  /// replayed plus one inter-message gap) so clock sync downstream sees time move forward
  bool loop = false;
  /// added to every receive time: a pass of `posed --replay --loop` after the first, which runs
  /// through a pipeline of its own, starts where the pass before it ended
  Duration time_shift = Duration::from_ns(0);
  /// shared by the replay's Sources: paced at recorded timing (rate is ignored) and re-stamped
  /// onto the host clock now; null: receive times are the recorded log times
  std::shared_ptr<ReplayTimeline> live_timeline;
  /// shared by the replay's Sources: a chunk one stream decompressed, the others read from memory
  std::shared_ptr<McapChunkCache> chunk_cache;
  /// > 0: a thread of the Source's own reads the stream this far (log time) ahead of read(), at
  /// most kReadAheadMessages messages; 0: read() reads the file itself
  Duration read_ahead = Duration::from_ns(0);
};

/// One raw channel of the stream, as recorded.
struct ReplayChannel {
  std::uint32_t source_channel = 0;
  std::string topic;
  std::string wire_format;
  /// everything in the Channel record's metadata (sensor config, calibration text)
  std::map<std::string, std::string> metadata;
};

class McapReplaySource final : public Source {
 public:
  /// The most messages read ahead at once (McapReplayConfig::read_ahead), whatever their span.
  static constexpr std::size_t kReadAheadMessages = 1024;
  /// The most buffers read() hands back to the read-ahead thread at once; more are freed.
  static constexpr std::size_t kSpareBuffers = 4;
  /// Messages from this size on (images) are copied into a buffer handed back; smaller ones
  /// (packets, metadata) into their own, so a packet never holds an image's buffer.
  static constexpr std::size_t kRecycledBytes = 64u << 10;

  explicit McapReplaySource(McapReplayConfig config);
  ~McapReplaySource() override;
  McapReplaySource(const McapReplaySource&) = delete;
  McapReplaySource& operator=(const McapReplaySource&) = delete;

  std::string_view name() const override { return name_; }
  /// Opens the file; fails when it is not MCAP, or when its summary lists no raw channel of the
  /// stream (the error names the streams it does hold). Starts the read-ahead thread, if any.
  bool open(std::string& error) override;
  ReadStatus read(RawChunk& chunk, Duration timeout) override;
  void request_stop() override;
  SourceCounters counters() const override;
  bool live() const override { return false; }
  /// as recorded in the channel's posed.wire_format (known once the channel was seen)
  std::string_view wire_format(std::uint32_t channel) const override;

  /// The stream's channels seen so far (all of them after open() when the summary is intact).
  std::vector<ReplayChannel> channels() const;
  /// "" or where and why the recording ended early.
  std::string damage() const;
  /// completed passes over the recording (loop)
  std::uint64_t passes() const { return passes_.load(std::memory_order_relaxed); }

  /// What the current (or last) pass delivered, in recorded log time (time_shift not added).
  struct DeliveredSpan {
    std::uint64_t messages = 0;
    std::int64_t first_log_ns = 0;
    std::int64_t last_log_ns = 0;
    /// between the last two messages (0 with fewer than two)
    std::int64_t last_gap_ns = 0;
  };
  /// Call when the Source is not being read (after the pipeline joined). With read-ahead, what
  /// was read from the file: the same once the stream has ended.
  DeliveredSpan delivered_span() const;
  /// With read-ahead: messages copied into a buffer read() had handed back (kRecycledBytes).
  std::uint64_t buffers_reused() const { return ahead_reused_.load(std::memory_order_relaxed); }

 private:
  /// One message read ahead: its bytes copied out of the reader's chunk.
  struct AheadMessage {
    std::vector<std::byte> bytes;
    std::uint32_t source_channel = 0;
    std::int64_t log_ns = 0;  // shifted by the loop offset
  };

  bool fetch();  // the next message of the stream into pending_, applying offset/duration/loop
  void read_ahead_loop();
  /// read() with read-ahead: the next message into current_; false at the end (ended_ set) or
  /// when none came within `timeout`.
  bool take_ahead(Duration timeout);
  bool wanted(const McapChannelRecord& c) const;
  void note_damage();

  McapReplayConfig config_;
  std::string name_;
  McapReader reader_;
  bool opened_ = false;
  bool ended_ = false;

  bool have_pending_ = false;
  McapMessage pending_;
  std::int64_t pending_log_ns_ = 0;           // shifted by the loop offset
  std::uint32_t pending_source_channel_ = 0;  // its channel's posed.source_channel

  bool have_first_ = false;
  std::int64_t first_log_ns_ = 0;  // the stream's first message in the file
  std::int64_t last_log_ns_ = 0, prev_log_ns_ = 0;
  std::int64_t pass_first_log_ns_ = 0;  // the first message delivered in this pass
  std::int64_t loop_shift_ns_ = 0;
  std::atomic<std::uint64_t> passes_{0};
  std::uint64_t delivered_this_pass_ = 0;

  // read-ahead: the reader thread fills ahead_, read() empties it into current_
  std::unique_ptr<SpscQueue<AheadMessage>> ahead_;
  // ... and hands the bytes it is done with back, for the reader thread to copy the next message
  // into: images are copied at 40 a second, and fresh half-megabyte blocks among the estimator's
  // long-lived allocations left the heap larger after one pass of a looped replay than another.
  std::unique_ptr<SpscQueue<std::vector<std::byte>>> spare_bytes_;
  std::atomic<bool> ahead_ended_{false};
  std::atomic<std::int64_t> ahead_base_log_ns_{0};  // log time of the newest message taken
  static constexpr std::int64_t kNoWake = std::numeric_limits<std::int64_t>::min();
  // the reader waits until read() takes a message this late (kNoWake: it does not wait)
  std::atomic<std::int64_t> ahead_wake_reader_at_ns_{kNoWake};
  std::atomic<bool> ahead_consumer_waiting_{false};  // read() waits for a message
  std::atomic<std::uint64_t> ahead_pushed_{0};       // messages the reader queued
  std::atomic<std::uint64_t> ahead_reused_{0};       // ... into a buffer handed back
  std::uint64_t ahead_taken_ = 0;                    // messages read() took (read()'s own)
  std::counting_semaphore<1 << 30> ahead_filled_{0}, ahead_room_{0};
  AheadMessage current_;
  bool have_current_ = false;
  std::thread reader_thread_;

  bool paced_ = false;
  HostTime anchor_host_;
  std::int64_t anchor_log_ns_ = 0;

  std::atomic<bool> stop_{false};
  std::mutex wait_mutex_;
  std::condition_variable wait_cv_;
  AtomicSourceCounters counts_;
  mutable std::mutex info_mutex_;
  std::string damage_;
  std::map<std::uint16_t, ReplayChannel> channels_;
};

}  // namespace posed::drivers::recording
