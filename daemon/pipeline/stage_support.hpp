#pragma once
// What the pipeline's stages share: the items on their queues (end-of-stream travels with the
// data), per-stream counters that the status snapshot reads from another thread, heartbeats for
// the systemd watchdog, and the small conversions every stage needs.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "core/estimator/nav_state.hpp"
#include "core/measurements.hpp"
#include "core/spsc_queue.hpp"
#include "core/sync/clock_sync.hpp"
#include "core/time.hpp"
#include "daemon/pipeline/pipeline_status.hpp"
#include "drivers/common/source.hpp"

namespace posed::pipeline {

/// How long a consumer sleeps when its queues are empty before it heartbeats again.
inline constexpr auto kStageWaitTimeout = std::chrono::milliseconds(50);
/// How long a Source read waits before the stage heartbeats again.
inline const Duration kStageReadTimeout = Duration::from_ms(100);

// `received`: the Source's receive stamp of the newest chunk that went into the measurement (the
// scan's last packet), for the latency figures (NavState::received).
struct ImuItem {
  ImuSample sample;
  bool end_of_stream = false;
  HostTime received;
  /// its stage's malformed + dropped count when it was queued (StreamCounters::bad()): a replay's
  /// health judges bad samples where the merge is, not where the stage has read ahead to
  std::uint64_t bad_before = 0;
};
struct ScanItem {
  LidarScan scan;
  bool end_of_stream = false;
  HostTime received;
  /// its stage's malformed + dropped count when it was queued (StreamCounters::bad()): a replay's
  /// health judges bad samples where the merge is, not where the stage has read ahead to
  std::uint64_t bad_before = 0;
};
struct ImageItem {
  Image image;
  bool end_of_stream = false;
  HostTime received;
  /// its stage's malformed + dropped count when it was queued (StreamCounters::bad()): a replay's
  /// health judges bad samples where the merge is, not where the stage has read ahead to
  std::uint64_t bad_before = 0;
};
struct StateItem {
  NavState state;
  bool end_of_stream = false;
  /// scans the fusion stage had handed the core when the core made the state: where the mapping
  /// stage's correction for it stands (mapping_stage.hpp)
  std::uint64_t scans_before = 0;
};

/// The last sign of life of one stage thread, on the host clock.
class Heartbeat {
 public:
  explicit Heartbeat(std::string name) : name_(std::move(name)) {}
  void beat();
  HostTime last() const { return HostTime::from_ns(ns_.load(std::memory_order_relaxed)); }
  const std::string& name() const { return name_; }
  void reset(HostTime now) { ns_.store(now.ns, std::memory_order_relaxed); }

 private:
  std::string name_;
  std::atomic<std::int64_t> ns_{0};
};

/// One sensor stream's counters, written by its stage thread, read by status() from any thread.
struct StreamCounters {
  std::atomic<std::uint64_t> received{0};     ///< chunks read from the Source
  std::atomic<std::uint64_t> decoded{0};      ///< measurements decoded
  std::atomic<std::uint64_t> malformed{0};    ///< frames/packets the decoder rejected
  std::atomic<std::uint64_t> dropped{0};      ///< measurements lost to a full queue or pool
  std::atomic<std::uint64_t> undecodable{0};  ///< chunks of a wire format no decoder knows
  std::atomic<bool> device_lost{false};

  /// Everything that counts against the stream's health: malformed, undecodable and dropped.
  std::uint64_t bad() const {
    return malformed.load(std::memory_order_relaxed) + undecodable.load(std::memory_order_relaxed) +
           dropped.load(std::memory_order_relaxed);
  }

  /// The clock figures, copied from the stage's ClockSync now and then.
  void publish_clock(const ClockSyncStatus& clock);
  ClockSyncStatus clock() const;

 private:
  mutable std::mutex clock_mutex_;
  ClockSyncStatus clock_;
};

/// What a stream's health is judged against between two reports (fill_stream_status()).
struct StreamHealthMemory {
  /// malformed + dropped at the last report
  std::uint64_t bad = 0;
  /// when that count last rose (unset: never)
  std::optional<HostTime> bad_rose;
  /// the health reported last, for the log's transitions ("" before the first report)
  std::string last_health;
  /// the stream was healthy (ok or degraded) at an earlier report: start-up is no news
  bool had_data = false;
};

/// A stream is no_data once its newest sample is this much older than `now`.
inline constexpr Duration kStreamStaleAfter = Duration::from_s(1);
/// ... and degraded until this long after its malformed or dropped count last rose.
inline constexpr Duration kStreamDegradedFor = Duration::from_s(2);

/// Fills `out` from the stage's counters and its Source's, judging its health at `now`: this
/// host's clock for a live Source, the newest sample of any stream in a replay (its data's
/// clock, whatever the replay speed), so silence and bad samples mean the same in both.
/// Health: device_lost; no_data (nothing decoded, or silent for kStreamStaleAfter); degraded
/// (malformed or dropped samples within kStreamDegradedFor); ok. Live, a change of health is
/// logged here.
/// `merged`: a replay's view from the fusion core's merge in stamp order (`now` is then the
/// merge's stamp): the merge waits for a silent stream, so only the merge passing it by shows
/// the silence, and a stage reads ahead of the merge, so its bad samples count from where the
/// merge takes the items they came before. The fusion stage logs those changes, exactly in the
/// data's time. Unset (live): the stream's clock sync's newest arrival and the stage's counts.
struct MergedStreamHealth {
  HostTime newest_stamp;  ///< the stream's newest stamp the fusion core took
  bool degraded = false;  ///< FusionCounters::degraded_by_stream
};
void fill_stream_status(StreamStatus& out, const StreamCounters& counters,
                        const drivers::Source& source, HostTime now, StreamHealthMemory& memory,
                        std::optional<MergedStreamHealth> merged = std::nullopt);

/// The bookkeeping every source stage does around Source::read(): heartbeat, the device lost and
/// back (logged once per transition), the received count, and chunks of a wire format the stage
/// has no decoder for (counted, logged once).
class SourceReader {
 public:
  SourceReader(std::string_view stream, drivers::Source& source, Heartbeat& heartbeat,
               StreamCounters& counters)
      : stream_(stream), source_(source), heartbeat_(heartbeat), counters_(counters) {}
  /// Reads until data or the end: true with `chunk` filled, false once the Source has ended.
  bool next(drivers::RawChunk& chunk);
  /// The wire format of `chunk`'s channel.
  std::string_view wire_format(const drivers::RawChunk& chunk) const {
    return source_.wire_format(chunk.channel);
  }
  /// Counts a chunk no decoder of the stage understands; says so once.
  void undecodable(const drivers::RawChunk& chunk);

 private:
  std::string_view stream_;
  drivers::Source& source_;
  Heartbeat& heartbeat_;
  StreamCounters& counters_;
  bool reported_lost_ = false;
  bool reported_format_ = false;
};

/// The config's clock kind name ("counter_us_32bit", ...) as ClockSync's enum.
DeviceClockKind clock_kind_from(const std::string& name);

/// Live Sources must never wait for the pipeline (queues drop the oldest); recordings and
/// generators must lose nothing, so their producer blocks instead (deterministic replays).
DropPolicy queue_policy(const drivers::Source* source);
/// How long a blocked producer of a recording waits before giving up on a stalled consumer.
inline constexpr auto kReplayBlockTimeout = std::chrono::seconds(30);

/// Logs a ClockSync event once per event ("imu clock: reset").
void log_clock_event(std::string_view stream, ClockEvent event);

}  // namespace posed::pipeline
