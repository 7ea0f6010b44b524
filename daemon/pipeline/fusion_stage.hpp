#pragma once
// The fusion stage (one thread): merges the measurement queues and drives the FusionCore
// (core/estimator/fusion_core.hpp), whose states go to the publisher's queue.
//
// Order. Each queue delivers its stream in stamp order (IMU sample stamp, scan end stamp, frame
// exposure stamp). With
// recordings as Sources (`in_stamp_order`), the stage merges the streams by stamp: it hands the
// core the oldest head only once every stream that has not ended has a head to compare with —
// a k-way merge that waits for the slowest stream. The core then sees one order, a function of
// the data alone, however the threads were scheduled: max-speed replays are deterministic. Live,
// waiting for the slowest sensor would add its period to every pose's latency, so the stage hands
// over whatever has arrived, oldest first, and the core's MeasurementGate orders the rest.
//
// Odometry (OdometryHandover): the states the core optimised are anchors for IMU-rate odometry,
// which runs on the IMU stage's thread live and on this one, in data order, in max-speed replays.

#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include "core/estimator/fusion_core.hpp"
#include "core/spsc_queue.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/imu_failover.hpp"
#include "daemon/pipeline/odometry_path.hpp"
#include "daemon/pipeline/scan_observer.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "daemon/pipeline/wakeup.hpp"

namespace posed::pipeline {

/// Figures the status snapshot reads from other threads.
struct FusionCounters {
  std::atomic<std::uint64_t> states{0};       ///< states the core produced
  std::atomic<std::uint64_t> scans_fused{0};  ///< scans handed to the core
  /// camera frames handed to the core, by CameraStream
  std::atomic<std::uint64_t> frames_fused[3] = {0, 0, 0};
  std::atomic<EstimatorMode> mode{EstimatorMode::kAligning};
  /// stamp of the newest measurement the core took: where the merge is (a replay's data clock)
  /// [ns]
  std::atomic<std::int64_t> newest_stamp_ns{0};
  /// the newest stamp the core took per stream: imu, lidar (a scan's end), visible, thermal,
  /// realsense_imu, depth [ns]. A replay's stream health: merged in stamp order, a stream that fell
  /// silent shows as the merge passing it by.
  std::atomic<std::int64_t> newest_stamp_by_stream_ns[6] = {0, 0, 0, 0, 0, 0};
  /// per stream, in stamp order (replays only): a malformed or dropped sample came before one
  /// the merge took within kStreamDegradedFor of its newest stamp
  std::atomic<bool> degraded_by_stream[6] = {false, false, false, false, false, false};
  /// the D435i IMU standing in for the A9 (imu_failover.hpp): now, how often, how many samples
  std::atomic<bool> imu_on_backup{false};
  std::atomic<std::uint64_t> imu_failovers{0};
  std::atomic<std::uint64_t> imu_backup_used{0};

  void publish_figures(const FusionFigures& f) {
    std::lock_guard lock(mutex_);
    figures_ = f;
  }
  FusionFigures figures() const {
    std::lock_guard lock(mutex_);
    return figures_;
  }

 private:
  mutable std::mutex mutex_;
  FusionFigures figures_;
};

/// Odometry from the back end's anchors (optimised states) instead of the core's own IMU
/// propagation, which waits behind every scan match. At most one is set.
struct OdometryHandover {
  /// live (and paced replays): the anchors go to the IMU stage's OdometryPath
  SpscQueue<AnchorItem>* anchors = nullptr;
  /// max-speed replays: this stage propagates each IMU sample itself, in data order, from the
  /// anchors released before it, so the odometry is the same on every run
  estimator::OdometryPropagator* in_order = nullptr;
};

struct FusionInputs {
  SpscQueue<ImuItem>* imu = nullptr;        ///< required
  SpscQueue<ScanItem>* scans = nullptr;     ///< null without a lidar
  SpscQueue<ImageItem>* visible = nullptr;  ///< null without the visible camera
  SpscQueue<ImageItem>* thermal = nullptr;  ///< null without the thermal camera
  /// the D435i's IMU, used while the A9 is silent; null without it or realsense_imu.failover
  SpscQueue<ImuItem>* backup_imu = nullptr;
  SpscQueue<ImageItem>* depth = nullptr;  ///< the D435i's depth images; null without them
};

/// A camera stream's index among the fusion stage's streams (imu, lidar, visible, thermal,
/// realsense_imu, depth).
constexpr std::size_t fusion_stream_index(CameraStream s) {
  return s == CameraStream::kVisible ? 2 : s == CameraStream::kThermal ? 3 : 5;
}

class FusionStage {
 public:
  FusionStage(const config::PosedConfig& config, std::unique_ptr<FusionCore> core,
              FusionInputs inputs, bool in_stamp_order, SpscQueue<StateItem>& states,
              Wakeup& inputs_ready, Wakeup& publisher, Heartbeat& heartbeat,
              FusionCounters& counters, OdometryHandover odometry = {},
              std::vector<ScanObserver*> scan_observers = {});
  /// Runs until every input stream has ended, then forwards end-of-stream to the publisher.
  void run();
  const FusionCore& core() const { return *core_; }

 private:
  template <class Item>
  class Lane;
  /// Hands the core every measurement the merge rule releases now; true if it handed any.
  bool dispatch_ready();
  /// Hands one IMU sample (the A9's or, standing in, the D435i's) to the odometry and the core.
  void hand_imu(const ImuItem& item);
  /// Hands the frame at the head of `lane`, of camera `stream`, to the core and counts it.
  void hand_image(Lane<ImageItem>& lane, CameraStream stream);
  /// Logs and counts a hand-over between the A9 and the D435i's IMU.
  void note_imu_switch();
  /// Logs a restart of the estimator's window since the last scan, with its reason.
  void note_reinitialisation();
  /// Routes the states the core produced: to the publisher and, as anchors, to the odometry.
  void route_states();
  void emit_states();

  const config::PosedConfig& config_;
  std::unique_ptr<FusionCore> core_;
  FusionInputs inputs_;
  bool in_stamp_order_;
  SpscQueue<StateItem>& states_;
  Wakeup& inputs_ready_;
  Wakeup& publisher_;
  Heartbeat& heartbeat_;
  FusionCounters& counters_;
  OdometryHandover odometry_;
  std::vector<ScanObserver*> scan_observers_;
  /// scans handed to the core so far [1]
  std::uint64_t scans_handed_ = 0;
  std::uint64_t reinitialisations_logged_ = 0;  // the estimator's restarts said so far
  /// per state in produced_ / outgoing_: scans_handed_ when the core made it
  std::vector<std::uint64_t> produced_scans_before_;
  std::vector<std::uint64_t> outgoing_scans_before_;
  /// Tags the states the last core call appended to produced_ with scans_handed_.
  void tag_new_states();
  std::vector<NavState> produced_;
  /// states for the publisher, routed from produced_
  std::vector<NavState> outgoing_;
  /// the newest receive stamp of everything handed to the core (NavState::received)
  HostTime newest_received_;
  /// the newest stamp the core took (FusionCounters::newest_stamp_ns)
  HostTime newest_stamp_;
  /// The core took `item` of `stream` (0..5: imu, lidar, visible, thermal, realsense_imu, depth):
  /// the newest stamps and receive time move on and, in stamp order, that stream is heard again if
  /// it was silent, and every stream the merge has passed by more than kStreamStaleAfter falls
  /// silent; a stream whose item counts more bad samples before it than the last is degraded until
  /// the merge has passed that by kStreamDegradedFor; all logged with the data's time.
  template <class Item>
  void took(std::size_t stream, const Item& item);
  static constexpr std::size_t kStreams = 6;
  /// per stream: it has delivered at least one sample
  bool heard_[kStreams] = {};
  /// per stream: its newest stamp (published as FusionCounters::newest_stamp_by_stream_ns)
  HostTime stream_stamp_[kStreams];
  /// per stream, in stamp order: the merge has passed its newest stamp by kStreamStaleAfter
  bool silent_[kStreams] = {};
  /// per stream, in stamp order: the bad count the newest item carried (Item::bad_before), when
  /// it last rose, and whether that is within kStreamDegradedFor of the merge
  std::uint64_t bad_seen_[kStreams] = {};
  HostTime bad_rose_[kStreams];
  bool degraded_[kStreams] = {};
  /// which IMU feeds the core, decided in data order
  ImuFailover failover_;
};

}  // namespace posed::pipeline
