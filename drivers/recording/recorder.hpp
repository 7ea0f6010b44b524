#pragma once
// Records what Sources read, and poses, to MCAP files (DESIGN.md, Recordings), off the Sources'
// threads: record() copies the bytes into a bounded lock-free queue per channel
// (core/spsc_queue.hpp) and returns at once; the Recorder's own thread drains every queue in
// log-time order into an McapWriter, rotates files by size or duration and fsyncs per policy.
//
// Drop policy: drop-newest. When the disk stalls long enough to fill a queue, the chunk that
// would not fit is refused on the Source's thread, which costs it nothing (no claim on the old
// slot, no free of an old buffer), and what is already queued, the older data, still reaches the
// file: a stall leaves one contiguous, counted hole per channel instead of a recording whose
// oldest part keeps being overwritten. Every drop is counted per channel.
//
// Raw channels follow raw_channels.hpp (topic /posed/raw/<stream>, encoding posed-raw, no schema,
// log time = host receive time). Poses are geometry_msgs/msg/PoseStamped (and Odometry) in CDR,
// logged on the host clock (stamp minus the recording's host-to-wall offset).
//
// Threading: add_*_channel(), write_pose() and counters() are safe from any thread; record()
// on one channel must come from one thread at a time (one producer per channel: its Source).

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/spsc_queue.hpp"
#include "core/time.hpp"
#include "drivers/common/source.hpp"
#include "drivers/recording/mcap_writer.hpp"

namespace posed::drivers::recording {

struct RecorderOptions {
  /// compression, chunk size, fsync every N chunks / on close
  McapWriterOptions writer;
  /// chunks queued per channel before record() drops (drop-newest) [items]
  std::size_t queue_capacity = 8192;
  /// start a new file once this one reaches this size; 0 = never [B]
  std::uint64_t rotate_bytes = 0;
  /// start a new file once it spans this much log time; 0 = never
  Duration rotate_after = Duration::from_ns(0);
  /// close the open chunk at least this often, so slow streams reach the disk (host clock);
  /// 0 = only when full, so the file's bytes depend on what was recorded alone, not on when
  Duration flush_interval = Duration::from_ms(1000);
  /// one producer thread whose push order is the file's message order (posectl sim): each pass
  /// of the writer thread takes only what was pushed before it began, in push order, so the
  /// file does not depend on how the threads were scheduled. Live recordings (several producers)
  /// keep false: each pass is ordered by log time.
  bool in_push_order = false;
  /// wall minus host time; when unset (0) it is sampled once in open()
  HostToWall host_to_wall{Duration::from_ns(0)};
  /// further Metadata records (name -> entries) written at the start of every file, e.g. how a
  /// simulated recording was made
  std::map<std::string, std::map<std::string, std::string>> metadata;
};

struct RecorderChannelCounters {
  std::string topic;
  std::uint64_t recorded = 0;  ///< messages accepted into the queue
  std::uint64_t dropped = 0;   ///< messages refused because the queue was full
  std::uint64_t bytes = 0;     ///< payload bytes accepted [B]
};

struct RecorderCounters {
  std::uint64_t messages_written = 0;  ///< messages handed to the writer
  std::uint64_t dropped = 0;           ///< sum over channels
  std::uint64_t files = 0;             ///< files opened (1 + rotations)
  std::uint64_t bytes_on_disk = 0;     ///< closed files plus the current one [B]
  std::uint64_t write_errors = 0;      ///< messages lost to write errors
  std::vector<RecorderChannelCounters> channels;
};

class Recorder {
 public:
  static constexpr std::uint16_t kInvalidChannel = 0xFFFF;
  /// most channels per recording
  static constexpr std::size_t kMaxChannels = 256;

  Recorder();
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Creates the first file and starts the writer thread. false + `error` on failure.
  bool open(const std::string& path, const RecorderOptions& options, std::string& error);

  /// A raw channel for one Source channel: returns its id, or kInvalidChannel when full. The
  /// same topic with the same metadata again returns the channel it already has.
  /// `metadata`: sensor config / calibration text / device, stored in the Channel record.
  std::uint16_t add_raw_channel(std::string_view stream, std::string_view wire_format,
                                const std::map<std::string, std::string>& metadata = {},
                                std::uint32_t source_channel = 0);
  /// Queues a copy of the chunk; never blocks. false when dropped (queue full) or bad id.
  bool record(std::uint16_t channel, const RawChunk& chunk);

  /// geometry_msgs/msg/PoseStamped on `topic` (created on first use). p [m], q = x, y, z, w.
  bool write_pose(std::string_view topic, WallTime stamp, std::string_view frame,
                  const std::array<double, 3>& p_m, const std::array<double, 4>& q_xyzw);
  /// nav_msgs/msg/Odometry on `topic` (ground truth, odometry); twist in the child frame.
  bool write_odometry(std::string_view topic, WallTime stamp, std::string_view frame,
                      std::string_view child_frame, const std::array<double, 3>& p_m,
                      const std::array<double, 4>& q_xyzw, const std::array<double, 3>& v_mps,
                      const std::array<double, 3>& w_radps);

  /// A channel of ROS 2 messages of `type_name` (one of ros2_schemas.hpp's, CDR with its ros2msg
  /// schema) on `topic`, e.g. "/tf": returns its id, or kInvalidChannel when full or the type is
  /// not one posed knows. `queue_capacity` 0: RecorderOptions::queue_capacity; large messages
  /// (point clouds) want fewer, so a stalled disk costs bounded memory.
  std::uint16_t add_ros2_channel(std::string_view topic, std::string_view type_name,
                                 std::size_t queue_capacity = 0);
  /// Queues a copy of `cdr` (encapsulation header included) on a channel from
  /// add_ros2_channel, logged at `stamp` on the host clock. Never blocks; false when dropped.
  /// One producer per channel, as record().
  bool write_ros2(std::uint16_t channel, WallTime stamp, std::span<const std::byte> cdr);
  /// Drains every queue, finishes the chunk, writes the summary and closes. Idempotent.
  /// false when a write failed (see error()).
  bool close();

  RecorderCounters counters() const;
  /// every file written so far, in order
  std::vector<std::string> files() const;
  /// the first write error, or empty
  std::string error() const;
  HostToWall host_to_wall() const { return options_.host_to_wall; }

 private:
  enum class Kind : std::uint8_t { kRaw, kPose, kOdometry, kRos2 };
  struct Item {
    std::int64_t log_time_ns = 0;
    /// order of push() across all channels: breaks log-time ties as the producers wrote them
    std::uint64_t order = 0;
    std::vector<std::byte> bytes;
  };
  struct Channel {
    Channel(std::size_t capacity) : queue(capacity, DropPolicy::kDropNewest) {}
    Kind kind = Kind::kRaw;
    std::string topic;
    /// ROS 2 type of a CDR channel (kPose, kOdometry, kRos2); empty for raw
    std::string schema_name;
    std::map<std::string, std::string> metadata;
    SpscQueue<Item> queue;
    std::atomic<std::uint64_t> bytes{0};
    std::uint32_t sequence = 0;  // writer thread only
  };

  std::uint16_t add_channel(Kind kind, std::string topic,
                            std::map<std::string, std::string> metadata,
                            std::string schema_name = {}, std::size_t queue_capacity = 0);
  std::uint16_t pose_channel(std::string_view topic, Kind kind);
  bool push(std::uint16_t id, std::int64_t log_time_ns, std::vector<std::byte> bytes);
  void run();
  bool open_file(std::string& error);
  void register_channels();
  void rotate();
  std::string file_name(std::uint64_t index) const;

  RecorderOptions options_;
  std::string base_path_;
  McapWriter writer_;
  std::uint64_t file_index_ = 0;
  std::size_t registered_in_file_ = 0;  // channels added to the current file
  std::int64_t file_first_log_ns_ = 0;
  bool file_has_messages_ = false;
  /// schema ids in the current file, by ROS 2 type name (writer thread only)
  std::map<std::string, std::uint16_t, std::less<>> schema_ids_;

  std::array<std::unique_ptr<Channel>, kMaxChannels> channels_;
  std::atomic<std::size_t> channel_count_{0};
  std::atomic<std::uint64_t> push_order_{0};
  /// in_push_order: one past the order of the newest item in a queue (one producer)
  std::atomic<std::uint64_t> pushed_before_{0};
  mutable std::mutex mutex_;  // channel registration, topic lookup, files_, error_
  std::map<std::string, std::uint16_t, std::less<>> pose_topics_;
  std::vector<std::string> files_;
  std::string error_;

  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<std::uint64_t> written_{0}, write_errors_{0}, closed_bytes_{0}, current_bytes_{0};
  bool open_ = false;
};

}  // namespace posed::drivers::recording
