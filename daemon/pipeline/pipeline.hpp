#pragma once
// The pipeline: Sources -> decoders -> clock sync -> queues -> fusion core -> outputs, one thread
// per stage (DESIGN.md, Data flow). The daemon and `posectl replay` build it with the same code;
// they differ only in the Sources passed in. Each stage lives in its own file:
//   imu_stage      Source -> A9 decoder -> ClockSync -> IMU queue
//   lidar_stage    Source -> Velodyne decoder -> ClockSync -> scan assembler -> scan queue
//   camera_stage   Source -> frame decoder -> camera clock -> image queue (visible, thermal)
//   fusion_stage   merge of the measurement queues -> FusionCore -> state queue
//   publisher_stage  states -> on_state, status snapshots -> on_status
//
// Stop protocol: request_stop() stops the Sources; each stage forwards end-of-stream through its
// queue after what it already holds, so everything measured is processed and published (drain).
// The daemon aborts on a second signal instead of waiting.

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/estimator/nav_state.hpp"
#include "core/fusion/camera_front_end.hpp"
#include "core/spsc_queue.hpp"
#include "core/time.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/mapping_stage.hpp"
#include "daemon/pipeline/odometry_path.hpp"
#include "daemon/pipeline/pipeline_status.hpp"
#include "daemon/pipeline/publisher_stage.hpp"
#include "daemon/pipeline/scan_observer.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "daemon/pipeline/wakeup.hpp"
#include "drivers/common/source.hpp"

namespace posed::fusion {
class CameraAidedCore;
}

namespace posed::pipeline {

class ImuStage;
class RealsenseImuStage;
class LidarStage;
class CameraStage;
class CameraLane;
class LidarHelper;
class FusionStage;
class PublisherStage;
struct LidarScanCounters;
struct FusionCounters;

struct PipelineSources {
  /// IMU bytes (live serial, synthetic, or replayed); required
  std::unique_ptr<drivers::Source> imu;
  /// VLP-32C UDP payloads, channel 0 data, 1 position (live UDP, pcap, or replayed); optional
  std::unique_ptr<drivers::Source> lidar;
  /// D435i colour frames (channel 0) and their D4xx metadata (channel 1); optional
  std::unique_ptr<drivers::Source> visible;
  /// PLUG 617 thermal frames (channel 0); optional
  std::unique_ptr<drivers::Source> thermal;
  /// the D435i's IMU: IIO HID accel (channel 0) and gyro (1) records; optional, the A9's backup
  std::unique_ptr<drivers::Source> realsense_imu;
  /// the D435i's depth node: Z16 frames (channel 0) and their D4xx metadata (1); optional
  std::unique_ptr<drivers::Source> depth;
  /// The Velodyne calibration the lidar stream was recorded with (its file's text, from the
  /// recording; `posed --replay FILE --recorded-config`), used instead of lidar.calibration so a
  /// replay decodes the packets as the robot did; empty: lidar.calibration as configured.
  std::string lidar_calibration_text;
  /// where that text came from, for messages
  std::string lidar_calibration_name;
  /// a keyframe map to localise on (posed --map DIR): the mapping stage localises on it instead
  /// of closing loops; null: none
  std::shared_ptr<const mapping::KeyframeMap> prior_map;
  /// recordings replayed at recorded timing (or N times it), not as fast as they go: the
  /// odometry then runs as it would live rather than waiting for the back end
  bool paced = false;
  /// a paced replay re-stamped onto the host clock now (posed --live-stamps): the pipeline takes
  /// its streams as it takes live ones (in arrival order, not merged by stamp, which would hold
  /// each scan back until the next one came), so what subscribers measure is the robot's latency
  bool live_stamps = false;

  /// The camera Source of a stream (null when absent).
  std::unique_ptr<drivers::Source>& camera(CameraStream s) {
    return s == CameraStream::kVisible ? visible : s == CameraStream::kThermal ? thermal : depth;
  }
  const drivers::Source* camera(CameraStream s) const {
    return const_cast<PipelineSources*>(this)->camera(s).get();
  }

  /// Calls `f(std::unique_ptr<drivers::Source>&)` on every slot above, set or not, so code that
  /// treats all Sources alike (the recording tap, `posectl record`) needs no list of its own:
  /// a new Source field must be added here too.
  template <class F>
  void for_each(F&& f) {
    f(imu);
    f(lidar);
    f(visible);
    f(thermal);
    f(realsense_imu);
    f(depth);
  }
};

/// Callbacks run on the publisher thread.
struct PipelineOutputs {
  /// every state (the daemon publishes propagation on rt/posed/odom and optimised states, or
  /// decimated propagation, on rt/posed/pose); without the odometry below, the propagation too.
  /// With the mapping stage's map -> odom for the state (identity without one).
  StateCallback on_state;
  /// IMU-rate odometry kept apart from the back end (publish.odom_decoupled, with a lidar),
  /// called on the IMU stage's thread; in max-speed replays it comes through on_state instead
  /// (made in data order on the fusion thread). Null: the core's own propagation, on_state.
  std::function<void(const NavState&)> on_odom;
  /// at publish.status_rate_hz, and once more at the end of the stream
  std::function<void(const PipelineStatus&)> on_status;
  /// keep a whole-run map for export_map() (posed --save-map); costs memory as the area grows
  bool keep_map = false;
  /// `posectl inspect frontend`: further camera front ends in these modes beside the
  /// configured one, on the same frames, for comparison (camera_compare_figures())
  std::vector<vision::FrontendMode> frontend_compare_modes;
  /// sees every frame a camera front end processed, on the fusion thread; must outlive the run
  fusion::FrontendObserver* frontend_observer = nullptr;
  /// looks at the core after every scan, on the fusion thread (rt/posed/cloud and map); must
  /// outlive the run
  ScanObserver* scan_observer = nullptr;
};

/// One queue between the stages, for the summary: whether any grew towards its capacity.
struct NamedQueueCounters {
  std::string name;  ///< "imu", "scans", "visible", "states", ...
  QueueCounters counters;
};

/// One stage's last sign of life, for the systemd watchdog.
struct StageBeat {
  /// "imu_source", "lidar_source", "visible_source", "mapping", "fusion", "publisher",
  /// "camera_frontend"
  std::string name;
  HostTime last;
};

class Pipeline {
 public:
  Pipeline(const config::PosedConfig& config, PipelineSources sources, PipelineOutputs outputs);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Opens the Sources and starts the threads. A Source that cannot open yet (device absent) is
  /// logged and retried by its thread; only a configuration that cannot work returns false.
  bool start(std::string& error);
  /// Drain: Sources stop, queued data flows through, threads end. Safe from any thread.
  void request_stop();
  /// True once every stage thread has finished.
  bool finished() const { return started_ && finished_stages_.load() == stages_.size(); }
  /// The stages this pipeline runs (the lidar stage only with a lidar Source), then the camera
  /// front end's thread when it has one (camera_frontend; known once start() has built the core).
  std::vector<std::string> stage_names() const;
  /// Joins the threads (call after finished() or request_stop()).
  void join();

  /// Last activity of each stage on the host clock, in stage_names() order.
  std::vector<StageBeat> stage_heartbeats() const;
  /// A snapshot, safe from any thread.
  PipelineStatus status() const;
  /// How rt/posed/odom is made (valid after start()): "imu_thread" (on_odom gets it),
  /// "in_order" (max-speed replay: from the anchors, on the fusion thread, through on_state) or
  /// "back_end" (the core's own propagation, through on_state).
  std::string_view odometry_mode() const {
    return odometry_ ? "imu_thread" : in_order_odometry_ ? "in_order" : "back_end";
  }
  /// Whether the fusion stage merges its streams by stamp (recordings and generators at full or
  /// recorded speed; deterministic) rather than taking them as they come (live, and replays with
  /// live stamps). Valid after start().
  bool merges_in_stamp_order() const { return in_stamp_order_; }
  /// The fusion core's one-line description (valid after start()).
  std::string estimator_description() const;
  /// The fusion core's map and keyframes (call after join(); empty without a lidar or keep_map).
  void export_map(MapExport& out) const;
  /// The mapping stage's loops and map -> odom (safe from any thread; nullopt without one).
  std::optional<MappingFigures> mapping_figures() const;
  /// The mapping stage's keyframes, optimised (call after join(); empty without one).
  std::vector<std::pair<HostTime, Eigen::Isometry3d>> optimised_keyframes() const;
  /// The mapping stage's map (after join(); empty without one, or when localising).
  mapping::KeyframeMap built_map() const;
  /// Localising: where base_link is in the map now (rt/initialpose); any thread. False without
  /// a prior map.
  bool set_initial_pose(const Eigen::Isometry3d& T_map_base);
  /// Every queue between the stages this pipeline has, with its counters (any thread).
  std::vector<NamedQueueCounters> queue_counters() const;
  /// The comparison front ends' figures (call after join(); empty without them).
  std::vector<CameraFigures> camera_compare_figures() const;

 private:
  /// Registers a stage: `make` builds it with its heartbeat and returns its thread's body.
  void add_stage(std::string name, const std::function<std::function<void()>(Heartbeat&)>& make);
  void launch(std::function<void()> body);

  config::PosedConfig config_;
  PipelineSources sources_;
  PipelineOutputs outputs_;
  SpscQueue<ImuItem> imu_queue_;
  /// the D435i IMU's samples to the fusion stage (with that Source and realsense_imu.failover)
  std::unique_ptr<SpscQueue<ImuItem>> backup_imu_queue_;
  /// the A9's newest sample stamp, for the D435i stage's live odometry hand-over [ns]
  std::atomic<std::int64_t> a9_newest_ns_{0};
  std::unique_ptr<SpscQueue<ScanItem>> scan_queue_;
  /// per CameraStream; null without that camera
  std::unique_ptr<SpscQueue<ImageItem>> image_queues_[3];  // by CameraStream
  SpscQueue<StateItem> state_queue_;
  /// signalled by every source stage: the fusion stage has input
  Wakeup fusion_ready_;
  Wakeup state_ready_;

  /// status(): each stream's health between reports (imu, lidar, visible, thermal,
  /// realsense_imu)
  mutable std::mutex health_mutex_;
  mutable StreamHealthMemory health_[6];  // by FusionStage stream index
  StreamCounters imu_counters_;
  StreamCounters realsense_imu_counters_;
  StreamCounters lidar_counters_;
  StreamCounters camera_counters_[3];
  std::unique_ptr<LidarScanCounters> scan_counters_;
  std::unique_ptr<FusionCounters> fusion_counters_;
  /// every stage this pipeline runs, in stage_names() order (add_stage())
  struct Stage {
    std::unique_ptr<Heartbeat> heartbeat;
    std::function<void()> run;
  };
  std::vector<Stage> stages_;

  std::unique_ptr<ImuStage> imu_stage_;
  std::unique_ptr<RealsenseImuStage> realsense_imu_stage_;
  std::unique_ptr<LidarStage> lidar_stage_;
  std::unique_ptr<CameraStage> camera_stages_[3];
  /// the camera front end's thread (frontend.own_thread) and its heartbeat; declared before the
  /// fusion stage, whose core posts to it, so it outlives that core
  Heartbeat camera_lane_beat_{"camera_frontend"};
  std::unique_ptr<CameraLane> camera_lane_;
  /// the scan match's helper threads (threads.lidar_helpers); before the fusion stage, whose
  /// core runs parts on them
  std::unique_ptr<LidarHelper> lidar_helper_;
  std::unique_ptr<FusionStage> fusion_stage_;
  /// the fusion core when it has cameras (owned by fusion_stage_)
  const fusion::CameraAidedCore* camera_core_ = nullptr;
  std::unique_ptr<PublisherStage> publisher_stage_;
  /// loop closure and map -> odom (mapping.loop_closure, with the lidar-inertial estimator)
  std::unique_ptr<MappingStage> mapping_stage_;
  /// odometry apart from the back end, live: its anchors and the IMU stage's path
  std::unique_ptr<SpscQueue<AnchorItem>> anchor_queue_;
  std::unique_ptr<OdometryPath> odometry_;
  /// the same in a max-speed replay, on the fusion stage's thread in data order
  std::unique_ptr<estimator::OdometryPropagator> in_order_odometry_;
  bool started_ = false;
  bool in_stamp_order_ = false;
  std::atomic<std::size_t> finished_stages_{0};
  std::vector<std::thread> threads_;
};

}  // namespace posed::pipeline
