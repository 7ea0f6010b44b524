#pragma once
// Where the pipeline's states and status go (run_daemon): rt/posed/odom, rt/posed/pose and
// rt/posed/status on DDS, /posed/odom and /posed/pose in the recording, and what the exit
// summary reads (counts, each topic's latency, the first and last odometry). A new sink is added
// here, not in run_daemon's wiring.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>

#include "core/estimator/nav_state.hpp"
#include "core/time.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/dds/messages.hpp"
#include "daemon/pipeline/latency_histogram.hpp"
#include "daemon/pipeline/pipeline_status.hpp"
#include "daemon/ros_outputs.hpp"

namespace posed {

namespace dds {
class Publisher;
}
namespace drivers::recording {
class Recorder;
}

/// One topic's latency at its DDS write (rt/posed/status, the summary).
struct TopicLatency {
  const char* topic;
  pipeline::LatencyHistogram receive_to_write;
  pipeline::LatencyHistogram stamp_age;

  /// Right after the write of a message made from `s`; `now` on the host clock.
  void record(const NavState& s, HostTime now) {
    if (s.received.ns != 0) receive_to_write.record(now - s.received);
    stamp_age.record(now - s.stamp);
  }
  dds::TopicLatencyMessage message(bool live) const {
    dds::TopicLatencyMessage m;
    m.topic = topic;
    m.count = stamp_age.count();
    m.live = live;
    if (!live) return m;
    const pipeline::LatencySummary r = receive_to_write.summary(), a = stamp_age.summary();
    m.receive_to_write_p50_ms = r.p50_ms;
    m.receive_to_write_p99_ms = r.p99_ms;
    m.receive_to_write_max_ms = r.max_ms;
    m.stamp_age_p50_ms = a.p50_ms;
    m.stamp_age_p99_ms = a.p99_ms;
    m.stamp_age_max_ms = a.max_ms;
    return m;
  }
  /// The summary's line: "rt/posed/odom  12000 written, receive->write p50 ... ms".
  std::string line(bool live) const {
    char buf[320];
    const dds::TopicLatencyMessage m = message(live);
    if (!live) {
      std::snprintf(buf, sizeof buf,
                    "%-14s %llu written; n/a (a replay's stamps are not this host's clock now: "
                    "--live-stamps)",
                    topic, static_cast<unsigned long long>(m.count));
    } else {
      std::snprintf(buf, sizeof buf,
                    "%-14s %llu written; receive->write p50 %.3f, p99 %.3f, max %.3f ms; stamp "
                    "age p50 %.3f, p99 %.3f, max %.3f ms",
                    topic, static_cast<unsigned long long>(m.count), m.receive_to_write_p50_ms,
                    m.receive_to_write_p99_ms, m.receive_to_write_max_ms, m.stamp_age_p50_ms,
                    m.stamp_age_p99_ms, m.stamp_age_max_ms);
    }
    return buf;
  }
};

/// What was published, for the summary (read after the threads end). Odometry is written by
/// one thread (the IMU stage's, or the publisher's when it is not decoupled), poses and status
/// by the publisher's.
struct PublishTally {
  std::atomic<std::uint64_t> odom{0};
  std::uint64_t pose = 0;
  std::uint64_t status = 0;
  std::atomic<std::uint64_t> failed{0};
  std::optional<NavState> first;
  std::optional<NavState> last;
  double distance_m = 0;
  HostTime next_pose_stamp;
  /// the newest pose's stamp: a pose stream's stamps only increase
  std::optional<HostTime> last_pose_stamp;
  /// optimised states not after the newest pose, left off pose (the first scan can end just
  /// before the IMU sample whose propagation went out while no optimised state had come) [1]
  std::uint64_t pose_out_of_order = 0;
  /// the estimator publishes optimised states (so pose is not decimated from odom)
  bool have_optimised = false;
};

class PoseSinks {
 public:
  /// `publisher` or `recorder` null: that sink is off. `live_clock`: the stamps are this host's
  /// clock now (live, or a replay with --live-stamps), so latencies can be measured.
  PoseSinks(const config::PosedConfig& config, dds::Publisher* publisher,
            drivers::recording::Recorder* recorder, HostToWall to_wall, HostTime started,
            bool live_clock);

  /// The clock conversion every stamp it publishes went through.
  const HostToWall& to_wall() const { return to_wall_; }

  /// IMU-rate odometry: rt/posed/odom (every publish.odom_decimation-th) and /posed/odom. From
  /// one thread at a time.
  void odom(const NavState& s);
  /// A state from the publisher stage: optimised ones on rt/posed/pose and /posed/pose, moved
  /// into the map frame by `T_map_odom` (the mapping stage's correction; rt/tf carries it as
  /// map -> odom); the back end's propagation (when odometry is not decoupled) to odom(), and
  /// decimated onto pose for an estimator without optimised states.
  void state(const NavState& s,
             const Eigen::Isometry3d& T_map_odom = Eigen::Isometry3d::Identity());
  /// rt/posed/status and rt/diagnostics, and the line for systemd's STATUS=.
  void status(const pipeline::PipelineStatus& st);
  /// rt/tf_static: base_link -> lidar, camera and thermal frames from the configured
  /// extrinsics. Once at start (transient-local: later readers get it too); in a replay with the
  /// first state, stamped with the data's time. Status and diagnostics, too, carry the data's
  /// time in a replay (the newest state's) and start with its first state.
  void static_transforms();

  /// The next `--replay --loop` pass begins (call while no pipeline runs): its estimate starts
  /// again from the origin, so the path starts afresh and the jump back is no distance travelled.
  void new_pass();

  /// The last status line ("starting" before the first status); safe from any thread.
  std::string status_line() const;
  const PublishTally& tally() const { return tally_; }
  const TopicLatency& odom_latency() const { return odom_latency_; }
  const TopicLatency& pose_latency() const { return pose_latency_; }
  bool live_clock() const { return live_clock_; }

 private:
  const config::PosedConfig& config_;
  dds::Publisher* publisher_;
  drivers::recording::Recorder* recorder_;
  HostToWall to_wall_;
  HostTime started_;
  bool live_clock_;
  Duration pose_period_;
  std::uint64_t odom_index_ = 0;
  /// the next odometry is a pass's first (new_pass())
  bool pass_start_ = false;
  HostTime next_tf_stamp_;
  /// publisher thread: the newest state's stamp (a replay's status carries it)
  std::optional<HostTime> newest_state_stamp_;
  /// a replay's static transforms wait for its first state
  bool static_pending_ = false;
  void publish_static_transforms(WallTime stamp);
  HostTime next_path_stamp_;
  PathBuilder path_;
  /// With each pose: rt/tf (rate-limited) and the path (published at publish.path_rate_hz).
  void ros_outputs(const NavState& s, const Eigen::Isometry3d& T_map_odom,
                   const dds::PoseMessage& pose);
  PublishTally tally_;
  TopicLatency odom_latency_{"rt/posed/odom", {}, {}};
  TopicLatency pose_latency_{"rt/posed/pose", {}, {}};
  mutable std::mutex status_line_mutex_;
  std::string status_line_ = "starting";
};

}  // namespace posed
