#include "daemon/pipeline/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/core/utility.hpp>

#include "core/estimator/fusion_core.hpp"
#include "core/estimator/lio_estimator.hpp"
#include "core/fusion/camera_aided_core.hpp"
#include "daemon/pipeline/camera_lane.hpp"
#include "daemon/pipeline/camera_stage.hpp"
#include "daemon/pipeline/estimator_config.hpp"
#include "daemon/pipeline/frontend_config.hpp"
#include "daemon/pipeline/fusion_stage.hpp"
#include "daemon/pipeline/imu_stage.hpp"
#include "daemon/pipeline/lidar_helper.hpp"
#include "daemon/pipeline/lidar_stage.hpp"
#include "daemon/pipeline/publisher_stage.hpp"
#include "daemon/pipeline/realsense_imu_stage.hpp"
#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"
#include "drivers/velodyne/calibration_loader.hpp"

namespace posed::pipeline {

namespace {

constexpr CameraStream kCameraStreams[] = {CameraStream::kVisible, CameraStream::kThermal,
                                           CameraStream::kDepth};
std::size_t index_of(CameraStream s) { return static_cast<std::size_t>(s); }
std::string stage_name(CameraStream s) { return std::string(to_string(s)) + "_source"; }

std::chrono::nanoseconds block_timeout(const drivers::Source* source) {
  return source && !source->live() ? std::chrono::nanoseconds(kReplayBlockTimeout)
                                   : std::chrono::nanoseconds(std::chrono::seconds(1));
}

/// A max-speed replay's IMU queues at most: the fusion stage merges its streams in stamp order and
/// propagates the odometry itself, so a deeper queue buys nothing but lets an IMU's reader run
/// seconds ahead of the other streams', beyond the chunks they share (McapChunkCache: with 1024
/// samples half the reads missed). 0.64 s at 200 Hz (the A9's, and the D435i's one sample per
/// gyro reading), longer than the scan queue's span.
/// A paced replay keeps the configured depth: there the IMU stage writes the odometry, and its
/// queue is what lets it run on while a heavy stage stalls (OdometryStallReplay).
constexpr std::size_t kMaxSpeedReplayImuCapacity = 128;

/// The queue of one IMU source (the A9's or the D435i's); `paced`: a replay at recorded timing.
std::size_t imu_capacity(const config::PosedConfig& c, const drivers::Source* imu, bool paced) {
  const auto configured = static_cast<std::size_t>(c.queues.imu_capacity);
  const bool max_speed_replay = imu != nullptr && !imu->live() && !paced;
  return max_speed_replay ? std::min(configured, kMaxSpeedReplayImuCapacity) : configured;
}

/// Lidar-inertial odometry when there is a lidar (also returned as `lio`, for the cameras to
/// join its window); IMU-only dead reckoning otherwise.
std::unique_ptr<FusionCore> make_core(const config::PosedConfig& c, bool have_lidar, bool keep_map,
                                      estimator::LioEstimator*& lio) {
  lio = nullptr;
  if (have_lidar) {
    estimator::LioConfig config = lio_config(c);
    config.keep_map = keep_map;
    auto core = std::make_unique<estimator::LioEstimator>(config);
    lio = core.get();
    return core;
  }
  return make_strapdown_core(strapdown_config(c));
}

/// `inner` with the camera front end beside it when a camera runs and the front end is on, and
/// the cameras in `lio`'s window when it is given and the coupling is on.
std::unique_ptr<FusionCore> with_cameras(std::unique_ptr<FusionCore> inner,
                                         estimator::LioEstimator* lio, const config::PosedConfig& c,
                                         bool has_visible, bool has_thermal, bool in_stamp_order,
                                         const PipelineOutputs& outputs,
                                         std::unique_ptr<CameraLane>& lane, Heartbeat& lane_beat,
                                         const fusion::CameraAidedCore*& camera_core) {
  camera_core = nullptr;
  if ((!has_visible && !has_thermal) || c.frontend.mode == "off") return inner;
  std::string note;
  fusion::CameraFrontEndConfig cameras =
      camera_front_end_config(c, has_visible, has_thermal, in_stamp_order, note);
  if (!note.empty()) POSED_LOG_WARN("frontend: %s", note.c_str());
  const fusion::CameraFactorsConfig factors = camera_factors_config(c, cameras);
  for (const vision::FrontendMode m : outputs.frontend_compare_modes) {
    if (std::find(cameras.compare_modes.begin(), cameras.compare_modes.end(), m) ==
            cameras.compare_modes.end() &&
        m != cameras.frontend.mode) {
      cameras.compare_modes.push_back(m);
    }
  }
  if (c.frontend.own_thread && lio != nullptr) {
    lane = std::make_unique<CameraLane>(c.threads.camera_frontend, 256, &lane_beat);
  }
  auto core = std::make_unique<fusion::CameraAidedCore>(std::move(inner), cameras, factors, lio,
                                                        lane.get());
  if (lane && !core->threaded()) lane.reset();  // the cameras are not in the window: no join
  core->cameras().set_observer(outputs.frontend_observer);
  camera_core = core.get();
  return core;
}

}  // namespace

Pipeline::Pipeline(const config::PosedConfig& config, PipelineSources sources,
                   PipelineOutputs outputs)
    : config_(config),
      sources_(std::move(sources)),
      outputs_(std::move(outputs)),
      imu_queue_(imu_capacity(config, sources_.imu.get(), sources_.paced),
                 queue_policy(sources_.imu.get()), block_timeout(sources_.imu.get())),
      state_queue_(static_cast<std::size_t>(config.queues.state_capacity),
                   queue_policy(sources_.imu.get()), block_timeout(sources_.imu.get())),
      scan_counters_(std::make_unique<LidarScanCounters>()),
      fusion_counters_(std::make_unique<FusionCounters>()) {
  if (sources_.lidar) {
    scan_queue_ = std::make_unique<SpscQueue<ScanItem>>(
        static_cast<std::size_t>(config.queues.scan_capacity), queue_policy(sources_.lidar.get()),
        block_timeout(sources_.lidar.get()));
  }
  if (sources_.realsense_imu && config.realsense_imu.failover) {
    backup_imu_queue_ = std::make_unique<SpscQueue<ImuItem>>(
        imu_capacity(config, sources_.realsense_imu.get(), sources_.paced),
        queue_policy(sources_.realsense_imu.get()), block_timeout(sources_.realsense_imu.get()));
  }
  for (const CameraStream s : kCameraStreams) {
    const drivers::Source* source = sources_.camera(s).get();
    if (source == nullptr) continue;
    image_queues_[index_of(s)] = std::make_unique<SpscQueue<ImageItem>>(
        static_cast<std::size_t>(config.queues.image_capacity), queue_policy(source),
        block_timeout(source));
  }
}

Pipeline::~Pipeline() {
  request_stop();
  join();
}

void Pipeline::add_stage(std::string name,
                         const std::function<std::function<void()>(Heartbeat&)>& make) {
  Stage stage;
  stage.heartbeat = std::make_unique<Heartbeat>(std::move(name));
  stage.run = make(*stage.heartbeat);
  stages_.push_back(std::move(stage));
}

std::vector<NamedQueueCounters> Pipeline::queue_counters() const {
  std::vector<NamedQueueCounters> out;
  out.push_back({"imu", imu_queue_.counters()});
  if (backup_imu_queue_) out.push_back({"realsense_imu", backup_imu_queue_->counters()});
  if (scan_queue_) out.push_back({"scans", scan_queue_->counters()});
  for (const CameraStream s : kCameraStreams) {
    if (const auto& q = image_queues_[index_of(s)])
      out.push_back({std::string(to_string(s)), q->counters()});
  }
  out.push_back({"states", state_queue_.counters()});
  if (anchor_queue_) out.push_back({"anchors", anchor_queue_->counters()});
  return out;
}

std::vector<std::string> Pipeline::stage_names() const {
  std::vector<std::string> names;
  for (const StageBeat& beat : stage_heartbeats()) names.push_back(beat.name);
  return names;
}

std::vector<StageBeat> Pipeline::stage_heartbeats() const {
  std::vector<StageBeat> beats;
  for (const auto& stage : stages_) {
    beats.push_back(StageBeat{stage.heartbeat->name(), stage.heartbeat->last()});
  }
  if (camera_lane_) beats.push_back(StageBeat{camera_lane_beat_.name(), camera_lane_beat_.last()});
  return beats;
}

void Pipeline::launch(std::function<void()> body) {
  threads_.emplace_back([this, body = std::move(body)] {
    body();
    finished_stages_.fetch_add(1);
  });
}

bool Pipeline::start(std::string& error) {
  if (!sources_.imu) {
    error = "no IMU source configured";
    return false;
  }
  drivers::velodyne::Calibration calibration;  // empty: the manual's table for the model seen
  if (sources_.lidar) {
    // The calibration recorded with the replayed packets, else the configured file, else none.
    const bool loaded = !sources_.lidar_calibration_text.empty()
                            ? drivers::velodyne::parse_calibration_text(
                                  sources_.lidar_calibration_text, sources_.lidar_calibration_name,
                                  calibration, error)
                            : config_.lidar.calibration.empty() ||
                                  drivers::velodyne::load_calibration(config_.lidar.calibration,
                                                                      calibration, error);
    if (!loaded) return false;
  }
  // Every stage is registered here, in the order stage_names() lists them (what the watchdog and
  // the summary show): its heartbeat, the object that runs on its thread, and its thread's body.
  add_stage("imu_source", [&](Heartbeat& beat) {
    imu_stage_ = std::make_unique<ImuStage>(config_, *sources_.imu, imu_queue_, fusion_ready_, beat,
                                            imu_counters_);
    return [this] { imu_stage_->run(); };
  });
  if (backup_imu_queue_) {
    add_stage("realsense_imu_source", [&](Heartbeat& beat) {
      realsense_imu_stage_ =
          std::make_unique<RealsenseImuStage>(config_, *sources_.realsense_imu, *backup_imu_queue_,
                                              fusion_ready_, beat, realsense_imu_counters_);
      return [this] { realsense_imu_stage_->run(); };
    });
  }
  if (sources_.lidar) {
    add_stage("lidar_source", [&](Heartbeat& beat) {
      lidar_stage_ = std::make_unique<LidarStage>(config_, std::move(calibration), *sources_.lidar,
                                                  *scan_queue_, fusion_ready_, beat,
                                                  lidar_counters_, *scan_counters_);
      return [this] { lidar_stage_->run(); };
    });
  }
  for (const CameraStream s : kCameraStreams) {
    if (!sources_.camera(s)) continue;
    add_stage(stage_name(s), [&](Heartbeat& beat) {
      const std::size_t i = index_of(s);
      camera_stages_[i] =
          std::make_unique<CameraStage>(config_, s, *sources_.camera(s), *image_queues_[i],
                                        fusion_ready_, beat, camera_counters_[i]);
      return [stage = camera_stages_[i].get()] { stage->run(); };
    });
  }
  // Recordings and generators: merge by stamp so replays are deterministic. Not a replay with
  // live stamps: merged by stamp, each scan would wait for the next (every stream must have
  // passed its end), and the poses would be a scan period later than on the robot.
  bool in_stamp_order = !sources_.imu->live() && !sources_.live_stamps;
  for (const drivers::Source* s :
       {sources_.lidar.get(), sources_.visible.get(), sources_.thermal.get(),
        sources_.realsense_imu.get(), sources_.depth.get()}) {
    if (s != nullptr && s->live()) in_stamp_order = false;
  }
  in_stamp_order_ = in_stamp_order;
  estimator::LioEstimator* lio = nullptr;
  std::unique_ptr<FusionCore> core =
      make_core(config_, sources_.lidar != nullptr, outputs_.keep_map, lio);
  if (lio != nullptr && config_.threads.lidar_helpers > 0) {
    lidar_helper_ = std::make_unique<LidarHelper>(
        config_.threads.lidar_helper, static_cast<std::size_t>(config_.threads.lidar_helpers));
    lio->set_splitter(lidar_helper_.get());
  }
  core = with_cameras(std::move(core), lio, config_, sources_.visible != nullptr,
                      sources_.thermal != nullptr, in_stamp_order, outputs_, camera_lane_,
                      camera_lane_beat_, camera_core_);
  // Odometry apart from the back end needs a back end with optimised states to anchor on (the
  // lidar-inertial one); IMU-only dead reckoning is itself the cheap propagation.
  OdometryHandover handover;
  if (config_.publish.odom_decoupled && lio != nullptr && outputs_.on_odom) {
    const estimator::LioConfig lio_settings = lio_config(config_);
    estimator::OdometryPropagatorConfig odometry;
    odometry.gravity_mps2 = lio_settings.gravity_mps2;
    odometry.accel_noise_density = lio_settings.noise.accel_noise_density;
    odometry.gyro_noise_density = lio_settings.noise.gyro_noise_density;
    if (lio_settings.backup_noise) {
      odometry.backup_accel_noise_density = lio_settings.backup_noise->accel_noise_density;
      odometry.backup_gyro_noise_density = lio_settings.backup_noise->gyro_noise_density;
    }
    odometry.blend_s = config_.publish.odom_blend_s;
    if (in_stamp_order && !sources_.paced) {
      // Max speed: the fusion stage propagates in data order (deterministic; no one waits).
      in_order_odometry_ = std::make_unique<estimator::OdometryPropagator>(odometry);
      handover.in_order = in_order_odometry_.get();
    } else {
      anchor_queue_ = std::make_unique<SpscQueue<AnchorItem>>(256, queue_policy(sources_.imu.get()),
                                                              block_timeout(sources_.imu.get()));
      odometry_ = std::make_unique<OdometryPath>(odometry, *anchor_queue_, outputs_.on_odom);
      imu_stage_->set_odometry(odometry_.get());
      if (realsense_imu_stage_) {
        imu_stage_->set_newest_stamp_out(&a9_newest_ns_);
        realsense_imu_stage_->set_odometry(odometry_.get(), &a9_newest_ns_);
      }
      handover.anchors = anchor_queue_.get();
    }
  }
  // Loops and map -> odom on a thread of their own, from the lidar-inertial estimate's scans.
  std::vector<ScanObserver*> scan_observers;
  if (outputs_.scan_observer != nullptr) scan_observers.push_back(outputs_.scan_observer);
  if ((config_.mapping.loop_closure || sources_.prior_map) && lio != nullptr) {
    add_stage("mapping", [&](Heartbeat& beat) {
      mapping_stage_ =
          std::make_unique<MappingStage>(config_, in_stamp_order, beat, sources_.prior_map);
      return [this] { mapping_stage_->run(); };
    });
    scan_observers.push_back(mapping_stage_.get());
  }
  add_stage("fusion", [&](Heartbeat& beat) {
    fusion_stage_ = std::make_unique<FusionStage>(
        config_, std::move(core),
        FusionInputs{&imu_queue_, scan_queue_.get(), image_queues_[0].get(), image_queues_[1].get(),
                     backup_imu_queue_.get(), image_queues_[2].get()},
        in_stamp_order, state_queue_, fusion_ready_, state_ready_, beat, *fusion_counters_,
        handover, std::move(scan_observers));
    return [this] { fusion_stage_->run(); };
  });
  add_stage("publisher", [&](Heartbeat& beat) {
    publisher_stage_ = std::make_unique<PublisherStage>(
        config_, state_queue_, state_ready_, beat, outputs_.on_state, outputs_.on_status,
        [this] { return status(); }, mapping_stage_.get());
    return [this] { publisher_stage_->run(); };
  });

  if (sources_.lidar) {
    std::string lidar_error;
    if (!sources_.lidar->open(lidar_error)) {
      POSED_LOG_WARN("lidar source not open yet: %s; retrying in the background",
                     lidar_error.c_str());
    }
  }
  for (const CameraStream s : kCameraStreams) {
    if (!sources_.camera(s)) continue;
    std::string camera_error;
    if (!sources_.camera(s)->open(camera_error)) {
      POSED_LOG_WARN("%s camera source not open yet: %s; retrying in the background",
                     to_string(s).data(), camera_error.c_str());
    }
  }
  if (backup_imu_queue_) {
    std::string rsimu_error;
    if (!sources_.realsense_imu->open(rsimu_error)) {
      POSED_LOG_WARN("D435i IMU source not open yet: %s; retrying in the background",
                     rsimu_error.c_str());
    }
  }
  std::string open_error;
  if (!sources_.imu->open(open_error)) {
    // The device may appear later (USB enumeration, cable): the Source retries on read().
    POSED_LOG_WARN("IMU source not open yet: %s; retrying in the background", open_error.c_str());
  }
  // OpenCV (the camera front end) would start a pool of worker threads of its own; the stages
  // are the threads this pipeline runs (their priorities and CPUs are configured), so OpenCV
  // runs sequentially on the fusion thread.
  cv::setNumThreads(0);
  const HostTime now = drivers::host_now();
  for (auto& stage : stages_) stage.heartbeat->reset(now);
  camera_lane_beat_.reset(now);
  started_ = true;
  for (auto& stage : stages_) launch(stage.run);
  return true;
}

void Pipeline::request_stop() {
  if (sources_.imu) sources_.imu->request_stop();
  if (sources_.lidar) sources_.lidar->request_stop();
  if (sources_.visible) sources_.visible->request_stop();
  if (sources_.thermal) sources_.thermal->request_stop();
  if (sources_.depth) sources_.depth->request_stop();
  if (sources_.realsense_imu) sources_.realsense_imu->request_stop();
}

void Pipeline::join() {
  for (auto& t : threads_) {
    if (t.joinable()) t.join();
  }
  threads_.clear();
}

void Pipeline::export_map(MapExport& out) const {
  if (fusion_stage_) fusion_stage_->core().export_map(out);
}

std::optional<MappingFigures> Pipeline::mapping_figures() const {
  if (!mapping_stage_) return std::nullopt;
  return mapping_stage_->figures();
}

std::vector<std::pair<HostTime, Eigen::Isometry3d>> Pipeline::optimised_keyframes() const {
  if (!mapping_stage_) return {};
  return mapping_stage_->optimised_keyframes();
}

mapping::KeyframeMap Pipeline::built_map() const {
  if (!mapping_stage_) return {};
  return mapping_stage_->built_map();
}

bool Pipeline::set_initial_pose(const Eigen::Isometry3d& T_map_base) {
  if (!mapping_stage_ || !sources_.prior_map) return false;
  mapping_stage_->set_initial_pose(T_map_base);
  return true;
}

std::vector<CameraFigures> Pipeline::camera_compare_figures() const {
  return camera_core_ ? camera_core_->cameras().compare_figures() : std::vector<CameraFigures>{};
}

std::string Pipeline::estimator_description() const {
  return fusion_stage_ ? std::string(fusion_stage_->core().description()) : std::string();
}

PipelineStatus Pipeline::status() const {
  if (!started_) return {};
  const HostTime now = drivers::host_now();
  // Health is judged on this host's clock live, on the data's in a replay: where the fusion
  // core's merge in stamp order is, which trails every stage however far the queues let one
  // stage read ahead, and which a silent stream's last stamp falls behind.
  const HostTime health_now =
      sources_.imu->live()
          ? now
          : HostTime::from_ns(fusion_counters_->newest_stamp_ns.load(std::memory_order_relaxed));
  const auto consumed = [&](std::size_t stream) -> std::optional<MergedStreamHealth> {
    if (sources_.imu->live()) return std::nullopt;
    return MergedStreamHealth{
        HostTime::from_ns(
            fusion_counters_->newest_stamp_by_stream_ns[stream].load(std::memory_order_relaxed)),
        fusion_counters_->degraded_by_stream[stream].load(std::memory_order_relaxed)};
  };
  std::lock_guard health_lock(health_mutex_);
  PipelineStatus st;
  st.stamp = now;
  st.mode = fusion_counters_->mode.load();
  st.states = fusion_counters_->states.load();
  st.states_dropped = state_queue_.counters().dropped();
  st.estimator = fusion_counters_->figures();
  if (mapping_stage_) {
    const MappingFigures m = mapping_stage_->figures();
    MappingStatus& ms = st.mapping.emplace();
    ms.localising = m.localising;
    ms.state = m.localising ? std::string(mapping::state_name(m.state)) : "mapping";
    ms.keyframes = m.loops.keyframes;
    ms.loops = m.loops.loops;
    ms.fixes = m.localisation.fixes;
    ms.correction_m = m.T_map_odom.translation().norm();
    ms.scans_skipped = m.keyframes_dropped;
  }

  StreamStatus imu;
  imu.name = "imu";
  fill_stream_status(imu, imu_counters_, *sources_.imu, health_now, health_[0], consumed(0));
  st.streams.push_back(std::move(imu));

  if (sources_.lidar) {
    StreamStatus lidar;
    lidar.name = "lidar";
    fill_stream_status(lidar, lidar_counters_, *sources_.lidar, health_now, health_[1],
                       consumed(1));
    st.streams.push_back(std::move(lidar));
    st.lidar_scans = scan_counters_->scans.load();
    st.lidar_points = scan_counters_->points.load();
    st.lidar_scans_cut_by_silence = scan_counters_->cut_by_silence.load();
    st.lidar_scans_implausible = scan_counters_->implausible.load();
    st.lidar_scans_fused = fusion_counters_->scans_fused.load();
  }
  for (const CameraStream s : kCameraStreams) {
    if (!sources_.camera(s)) continue;
    StreamStatus camera;
    camera.name = std::string(to_string(s));
    fill_stream_status(camera, camera_counters_[index_of(s)], *sources_.camera(s), health_now,
                       health_[fusion_stream_index(s)], consumed(fusion_stream_index(s)));
    st.streams.push_back(std::move(camera));
    st.camera_frames_fused[index_of(s)] = fusion_counters_->frames_fused[index_of(s)].load();
  }
  if (backup_imu_queue_) {
    StreamStatus rsimu;
    rsimu.name = "realsense_imu";
    fill_stream_status(rsimu, realsense_imu_counters_, *sources_.realsense_imu, health_now,
                       health_[4], consumed(4));
    st.streams.push_back(std::move(rsimu));
    st.imu_in_use = fusion_counters_->imu_on_backup.load() ? "d435i" : "a9";
    st.imu_failovers = fusion_counters_->imu_failovers.load();
    st.imu_backup_used = fusion_counters_->imu_backup_used.load();
  }
  return st;
}

}  // namespace posed::pipeline
