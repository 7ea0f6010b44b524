#include "daemon/run_daemon.hpp"

#include <signal.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "daemon/build_info.hpp"
#include "daemon/dds/publisher.hpp"
#include "daemon/estimator_summary.hpp"
#include "daemon/notify/sd_notify.hpp"
#include "daemon/notify/stage_watchdog.hpp"
#include "daemon/pipeline/camera_calibration.hpp"
#include "daemon/pipeline/camera_stage.hpp"
#include "daemon/pipeline/latency_histogram.hpp"
#include "daemon/pipeline/pipeline.hpp"
#include "daemon/pipeline/recording_tap.hpp"
#include "daemon/pipeline/source_factory.hpp"
#include "drivers/camera/libusb_transport.hpp"
#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"
#include "drivers/recording/map_files.hpp"
#include "drivers/recording/recorder.hpp"

namespace posed {
namespace {

std::array<double, 36> to_row_major(const Eigen::Matrix<double, 6, 6>& m) {
  std::array<double, 36> out{};
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) out[static_cast<std::size_t>(r * 6 + c)] = m(r, c);
  }
  return out;
}

double yaw_deg(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x()) * 180.0 / M_PI;
}

/// What was published, for the summary (read by main after the threads end). Odometry is
/// written by one thread (the IMU stage's, or the publisher's when it is not decoupled), poses
/// and status by the publisher's.
struct PublishTally {
  std::atomic<std::uint64_t> odom{0};
  std::uint64_t pose = 0;
  std::uint64_t status = 0;
  std::atomic<std::uint64_t> failed{0};
  std::optional<NavState> first;
  std::optional<NavState> last;
  double distance_m = 0;
  HostTime next_pose_stamp;
  /// the estimator publishes optimised states (so pose is not decimated from odom)
  bool have_optimised = false;
};

/// Writes the map and keyframes the fusion core kept; false (logged) when there is none or a
/// file cannot be written. `line` gets the summary line.
bool save_map(const pipeline::Pipeline& pipe, const std::string& map_path, HostToWall to_wall,
              std::string& line) {
  MapExport map;
  pipe.export_map(map);
  if (map.keyframes.empty()) {
    POSED_LOG_ERROR("--save-map %s: no map was built (%s)", map_path.c_str(),
                    "no lidar scan was matched; a map needs the lidar-inertial estimator");
    line = "none (no lidar scan was matched)";
    return false;
  }
  std::string error;
  std::vector<drivers::recording::StampedTransform> keyframes;
  keyframes.reserve(map.keyframes.size());
  for (const auto& k : map.keyframes) keyframes.push_back({to_wall(k.stamp), k.T_map_base});
  const std::string keyframes_path = keyframes_path_for(map_path);
  if (!drivers::recording::write_pcd(map_path, map.points_map_m, error) ||
      !drivers::recording::write_tum(keyframes_path, keyframes, error)) {
    POSED_LOG_ERROR("--save-map: %s", error.c_str());
    line = "failed: " + error;
    return false;
  }
  char buf[512];
  std::snprintf(buf, sizeof buf, "%zu points (%.2f m voxels) to %s, %zu keyframes to %s",
                map.points_map_m.size(), map.voxel_m, map_path.c_str(), keyframes.size(),
                keyframes_path.c_str());
  line = buf;
  return true;
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

}  // namespace

std::string keyframes_path_for(const std::string& map_path) {
  const std::string ext = ".pcd";
  if (map_path.size() > ext.size() &&
      map_path.compare(map_path.size() - ext.size(), ext.size(), ext) == 0) {
    return map_path.substr(0, map_path.size() - ext.size()) + ".keyframes.tum";
  }
  return map_path + ".keyframes.tum";
}

int run_daemon(const config::PosedConfig& configured, const RunOptions& options) {
  // What runs: the configuration, with what the devices say of themselves (calibration).
  config::PosedConfig config = configured;
  // Signals are taken synchronously by this thread; the stage threads inherit the mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  const HostTime started = drivers::host_now();
  HostToWall to_wall{drivers::wall_now() - WallTime::from_ns(started.ns)};
  const bool replaying = !options.replay.path.empty();

  dds::DdsConfig dds_config;
  dds_config.domain_id = static_cast<std::uint32_t>(config.dds.domain_id);
  dds_config.map_frame = config.dds.map_frame;
  dds_config.base_frame = config.dds.base_frame;
  dds_config.cyclonedds_xml_path = config.dds.cyclonedds_config;
  std::string error;
  std::unique_ptr<dds::Publisher> publisher;
  if (options.publish_dds) publisher = dds::Publisher::create(dds_config, error);
  if (options.publish_dds && !publisher) {
    POSED_LOG_ERROR("cannot start DDS: %s", error.c_str());
    return 1;
  }

  pipeline::BuiltSources built;
  std::string replay_streams;
  if (replaying) {
    pipeline::ReplaySources replay = pipeline::make_replay_sources(options.replay, error);
    // Replayed stamps are the recording's host clock; its wall offset keeps the DDS stamps (and
    // so the ground truth of a simulated run) in the recorded time base.
    // With --live-stamps the stamps are this host's clock now, and so is the wall offset.
    if (replay.have_host_to_wall && !options.replay.live_stamps) to_wall = replay.host_to_wall;
    built = std::move(replay.built);
    replay_streams = replay.streams;
    if (options.replay.recorded_config) {
      POSED_LOG_INFO("configuration as recorded in %s%s%s", options.replay.path.c_str(),
                     built.sources.lidar_calibration_text.empty() ? "" : "; lidar calibration: ",
                     built.sources.lidar_calibration_name.c_str());
    }
  } else {
    if (config.visible_camera.enabled && config.visible_camera.source == "v4l2") {
      drivers::camera::LibusbTransport usb;
      const std::string line = pipeline::apply_d435i_factory_calibration(config, usb);
      if (!line.empty()) POSED_LOG_INFO("%s", line.c_str());
    }
    built = pipeline::make_sources(config, error);
  }
  if (!built.sources.imu) {
    POSED_LOG_ERROR("%s", error.c_str());
    return 1;
  }
  // Owned by the pipeline, which outlives every use below.
  const drivers::SyntheticImuSource* synthetic = built.synthetic;

  std::unique_ptr<drivers::recording::Recorder> recorder;
  if (!options.record_path.empty()) {
    recorder = std::make_unique<drivers::recording::Recorder>();
    drivers::recording::RecorderOptions recorder_options;
    recorder_options.host_to_wall = to_wall;
    if (!recorder->open(options.record_path, recorder_options, error)) {
      POSED_LOG_ERROR("cannot record: %s", error.c_str());
      return 1;
    }
    pipeline::tap_sources(built.sources, *recorder, config);
    POSED_LOG_INFO("recording raw streams and poses to %s", options.record_path.c_str());
  }

  PublishTally tally;
  // Stamps are this host's clock now live and in a replay with --live-stamps; otherwise a
  // recording's, and how late a message is cannot be told from them.
  const bool live_clock = !replaying || options.replay.live_stamps;
  TopicLatency odom_latency{"rt/posed/odom", {}, {}};
  TopicLatency pose_latency{"rt/posed/pose", {}, {}};
  const Duration pose_period = Duration::from_seconds(1.0 / config.publish.pose_rate_hz);
  std::uint64_t odom_index = 0;
  // IMU-rate propagation on rt/posed/odom: on the IMU stage's thread when odometry is kept apart
  // from the back end, else on the publisher's.
  const auto publish_odom = [&](const NavState& s) {
    if (tally.last) tally.distance_m += (s.p_map_base_m - tally.last->p_map_base_m).norm();
    if (!tally.first) tally.first = s;
    tally.last = s;
    if (odom_index++ % static_cast<std::uint64_t>(config.publish.odom_decimation) != 0) return;
    const WallTime stamp = to_wall(s.stamp);
    if (publisher) {
      dds::OdomMessage odom;
      odom.stamp = stamp;
      odom.p_map_base_m = s.p_map_base_m;
      odom.q_map_base = s.q_map_base;
      odom.v_base_mps = s.q_map_base.conjugate() * s.v_map_mps;
      odom.w_base_radps = s.w_base_radps;
      odom.pose_covariance = to_row_major(s.pose_covariance);
      odom.twist_covariance = to_row_major(s.twist_covariance);
      if (publisher->publish_odom(odom)) {
        odom_latency.record(s, drivers::host_now());
        tally.odom.fetch_add(1, std::memory_order_relaxed);
      } else {
        tally.failed.fetch_add(1, std::memory_order_relaxed);
      }
    }
    if (recorder) {
      // After the write: the recording must never delay the odometry.
      const Eigen::Quaterniond& q = s.q_map_base;
      const Eigen::Vector3d v_base = s.q_map_base.conjugate() * s.v_map_mps;
      recorder->write_odometry("/posed/odom", stamp, config.dds.map_frame, config.dds.base_frame,
                               {s.p_map_base_m.x(), s.p_map_base_m.y(), s.p_map_base_m.z()},
                               {q.x(), q.y(), q.z(), q.w()}, {v_base.x(), v_base.y(), v_base.z()},
                               {s.w_base_radps.x(), s.w_base_radps.y(), s.w_base_radps.z()});
    }
  };
  pipeline::PipelineOutputs outputs;
  outputs.keep_map = !options.map_path.empty();
  outputs.on_odom = publish_odom;
  outputs.on_state = [&](const NavState& s) {
    const WallTime stamp = to_wall(s.stamp);
    // Optimised states (one per scan) go on rt/posed/pose; IMU propagation (when the back end
    // makes it) on rt/posed/odom. An estimator without optimised states (strapdown) has its
    // propagation decimated onto pose.
    if (s.optimised) tally.have_optimised = true;
    if (!s.optimised) publish_odom(s);
    const bool pose_now =
        s.optimised || (!tally.have_optimised && s.stamp >= tally.next_pose_stamp);
    if (pose_now) {
      tally.next_pose_stamp = s.stamp + pose_period;
      dds::PoseMessage pose;
      pose.stamp = stamp;
      pose.p_map_base_m = s.p_map_base_m;
      pose.q_map_base = s.q_map_base;
      if (!publisher) {
        // offline run: nothing to publish
      } else if (publisher->publish_pose(pose)) {
        pose_latency.record(s, drivers::host_now());
        ++tally.pose;
      } else {
        tally.failed.fetch_add(1, std::memory_order_relaxed);
      }
      if (recorder) {
        const Eigen::Quaterniond& q = s.q_map_base;
        recorder->write_pose("/posed/pose", stamp, config.dds.map_frame,
                             {s.p_map_base_m.x(), s.p_map_base_m.y(), s.p_map_base_m.z()},
                             {q.x(), q.y(), q.z(), q.w()});
      }
    }
  };
  std::mutex status_line_mutex;
  std::string status_line = "starting";
  outputs.on_status = [&](const pipeline::PipelineStatus& st) {
    dds::StatusMessage msg;
    msg.stamp = to_wall(st.stamp);
    msg.version = std::string(version_string());
    msg.estimator_mode = std::string(to_string(st.mode));
    const FusionFigures& f = st.estimator;
    msg.estimator = {
        f.scans_used,        f.scans_rejected, f.scans_degenerate,      f.scans_skipped,
        f.reinitialisations, f.keyframes,      f.degenerate_directions, f.gyro_bias_radps,
        f.accel_bias_mps2};
    const CameraFigures& cam = f.camera;
    msg.camera.mode = std::string(cam.mode);
    msg.camera.frames = cam.frames;
    msg.camera.frames_unusable = cam.frames_unusable + cam.frames_without_imu;
    msg.camera.features = cam.features;
    msg.camera.depth_associated = cam.depth_associated;
    msg.camera.match_success_rate = cam.match_success_rate();
    for (std::size_t i = 0; i < 3; ++i) {
      msg.camera.confidence[i] = cam.quality[i].valid ? cam.quality[i].confidence : 0.0;
      msg.camera.omega[i] = cam.quality[i].valid ? cam.quality[i].omega : 0.0;
    }
    msg.modalities = modality_names(f.modalities);
    for (std::size_t i = 0; i < 3; ++i) {
      const VisualStreamFigures& v = f.visual[i];
      msg.visual[i] = {v.configured,
                       v.active,
                       v.omega,
                       v.confidence,
                       v.factors,
                       v.failed + v.no_frames + v.implausible,
                       v.gated_out,
                       v.left,
                       v.rejoined,
                       v.inliers,
                       v.reprojection_rms_px,
                       v.residual_median};
    }
    msg.selection = {f.selection.lidar_visual_inertial, f.selection.lidar_inertial,
                     f.selection.visual_inertial, f.selection.imu_only,
                     f.selection.last_threshold_m};
    msg.uptime_s = (st.stamp - started).seconds();
    msg.latency = {odom_latency.message(live_clock), pose_latency.message(live_clock)};
    std::string line = std::string(to_string(st.mode));
    for (const auto& s : st.streams) {
      dds::StreamStatusMessage m;
      m.name = s.name;
      m.rate_hz = s.rate_hz;
      m.received = s.received;
      m.decoded = s.decoded;
      m.dropped = s.dropped;
      m.malformed = s.malformed;
      m.clock_offset_ns = s.clock_offset_ns;
      m.clock_drift_ppm = s.clock_drift_ppm;
      m.clock_jitter_ns = s.clock_jitter_ns;
      m.clock_uncertainty_ns = s.clock_uncertainty_ns;
      m.clock_state = s.clock_state;
      m.health = s.health;
      msg.streams.push_back(std::move(m));
      char part[160];
      std::snprintf(part, sizeof part, "; %s %.0f Hz %s clock %s", s.name.c_str(), s.rate_hz,
                    s.health.c_str(), s.clock_state.c_str());
      line += part;
    }
    char odom_part[64];
    std::snprintf(odom_part, sizeof odom_part, "; %llu odom published",
                  static_cast<unsigned long long>(tally.odom.load()));
    line += odom_part;
    msg.summary = line;
    if (!publisher) {
      // offline run: nothing to publish
    } else if (publisher->publish_status(msg)) {
      ++tally.status;
    } else {
      tally.failed.fetch_add(1, std::memory_order_relaxed);
    }
    std::lock_guard lock(status_line_mutex);
    status_line = line;
  };

  const bool built_has_lidar = built.sources.lidar != nullptr;
  // A replay at full speed can be over before discovery has matched a reader that was already
  // waiting for it (volatile durability: samples before the match are not delivered). Give such
  // readers a moment to match first; live data has no beginning worth waiting for.
  const double wait_s = options.wait_subscribers_s >= 0 ? options.wait_subscribers_s
                        : replaying                     ? 1.0
                                                        : 0.0;
  if (publisher && wait_s > 0) {
    const HostTime give_up = drivers::host_now() + Duration::from_seconds(wait_s);
    while (publisher->matched_subscribers(dds::Topic::kOdom) == 0 &&
           publisher->matched_subscribers(dds::Topic::kPose) == 0 &&
           drivers::host_now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  pipeline::Pipeline pipe(config, std::move(built.sources), std::move(outputs));
  const HostTime pipeline_started = drivers::host_now();
  if (!pipe.start(error)) {
    POSED_LOG_ERROR("cannot start the pipeline: %s", error.c_str());
    return 1;
  }

  notify::SdNotifier notifier;
  notify::StageWatchdog watchdog;
  // Only the stages this pipeline runs are watched; a stage that never started cannot stall.
  std::vector<notify::StageWatchdog::StageId> watched;
  for (const std::string& stage : pipe.stage_names()) {
    watched.push_back(watchdog.register_stage(
        stage, Duration::from_seconds(config.watchdog.stage_deadline_s), started));
  }
  notify::WatchdogPinger pinger(notifier.watchdog_interval());
  notifier.notify("READY=1\nSTATUS=sources open, aligning");
  char dds_part[128] = "offline, no DDS";
  if (publisher) {
    std::snprintf(dds_part, sizeof dds_part,
                  "on DDS domain %d (rt/posed/odom, rt/posed/pose, rt/posed/status)",
                  config.dds.domain_id);
  }
  if (replaying) {
    POSED_LOG_INFO("replaying %s (%s) %s", options.replay.path.c_str(), replay_streams.c_str(),
                   dds_part);
  } else {
    POSED_LOG_INFO("running: imu %s%s %s", config.imu.source.c_str(),
                   config.lidar.enabled ? ", lidar" : "", dds_part);
  }

  int exit_code = 0;
  bool stopping = false;
  HostTime next_status_line = started + Duration::from_s(1);
  const timespec poll_period{0, 100'000'000};
  while (!pipe.finished()) {
    siginfo_t info{};
    const int sig = sigtimedwait(&signals, &info, &poll_period);
    const HostTime now = drivers::host_now();
    if (sig == SIGTERM || sig == SIGINT) {
      if (stopping) {
        POSED_LOG_ERROR("second %s: aborting without draining", strsignal(sig));
        std::_Exit(128 + sig);
      }
      POSED_LOG_INFO("%s: draining and stopping", strsignal(sig));
      notifier.notify("STOPPING=1\nSTATUS=draining");
      stopping = true;
      pipe.request_stop();
    } else if (sig == SIGHUP) {
      POSED_LOG_NOTICE("SIGHUP: no setting can be reloaded while running yet; restart to apply");
    }
    if (!stopping && !replaying && options.duration_s > 0 &&
        (now - started).seconds() >= options.duration_s) {
      POSED_LOG_INFO("--duration %.1f s reached: draining and stopping", options.duration_s);
      notifier.notify("STOPPING=1\nSTATUS=draining");
      stopping = true;
      pipe.request_stop();
    }
    const std::vector<pipeline::StageBeat> beats = pipe.stage_heartbeats();
    for (std::size_t i = 0; i < watched.size() && i < beats.size(); ++i) {
      watchdog.heartbeat(watched[i], beats[i].last);
    }
    std::string line;
    {
      std::lock_guard lock(status_line_mutex);
      line = status_line;
    }
    if (const auto message = pinger.poll(now, watchdog.check(now), line)) notifier.notify(*message);
    // While a stage stalls the pinger's STATUS= names it; ours would hide that.
    if (now >= next_status_line && !pinger.reporting_stall()) {
      next_status_line = now + Duration::from_s(1);
      notifier.notify("STATUS=" + line);
    }
  }
  pipe.join();
  if (recorder && !recorder->close()) {
    POSED_LOG_ERROR("recording %s: %s", options.record_path.c_str(), recorder->error().c_str());
    exit_code = 1;
  }
  std::string map_line;
  if (!options.map_path.empty() && !save_map(pipe, options.map_path, to_wall, map_line))
    exit_code = 1;

  // The summary a person reads at the end of a run.
  const pipeline::PipelineStatus st = pipe.status();
  const double run_s = (drivers::host_now() - started).seconds();
  std::printf("\nposed summary\n");
  std::printf("  run time            %.1f s\n", run_s);
  std::printf("  estimator           %s, last mode %s\n", pipe.estimator_description().c_str(),
              std::string(to_string(st.mode)).c_str());
  for (const auto& s : st.streams) {
    // Chunks nothing could decode are a configuration problem, not damaged data: said apart.
    char undecodable[80] = "";
    if (s.undecodable > 0) {
      std::snprintf(undecodable, sizeof undecodable, " (%llu with no decoder configured)",
                    static_cast<unsigned long long>(s.undecodable));
    }
    std::printf(
        "  %-19s %llu decoded (%.1f Hz mean), %llu malformed%s, %llu dropped; clock %s, "
        "offset %.3f ms, drift %.1f ppm\n",
        s.name.c_str(), static_cast<unsigned long long>(s.decoded),
        run_s > 0 ? static_cast<double>(s.decoded) / run_s : 0.0,
        static_cast<unsigned long long>(s.malformed), undecodable,
        static_cast<unsigned long long>(s.dropped), s.clock_state.c_str(),
        static_cast<double>(s.clock_offset_ns) * 1e-6, s.clock_drift_ppm);
  }
  if (replaying) {
    std::printf("  replayed            %s (%s)\n", options.replay.path.c_str(),
                replay_streams.c_str());
    // What a replay costs: the span of data turned into poses per second of wall time.
    const double processing_s = (drivers::host_now() - pipeline_started).seconds();
    if (tally.first && tally.last && processing_s > 0) {
      const double span_s = (tally.last->stamp - tally.first->stamp).seconds();
      std::printf("  real-time factor    %.2fx (%.1f s of data in %.1f s)\n", span_s / processing_s,
                  span_s, processing_s);
    }
  }
  if (built_has_lidar) {
    std::printf(
        "  lidar scans         %llu assembled (%.0f points/scan mean), %llu reached the "
        "fusion core, %llu used by the estimator\n",
        static_cast<unsigned long long>(st.lidar_scans),
        st.lidar_scans ? static_cast<double>(st.lidar_points) / static_cast<double>(st.lidar_scans)
                       : 0.0,
        static_cast<unsigned long long>(st.lidar_scans_fused),
        static_cast<unsigned long long>(st.estimator.scans_used));
  }
  if (built_has_lidar) {
    const FusionFigures& f = st.estimator;
    std::printf(
        "  scan matching       %llu used, %llu rejected, %llu degenerate, %llu skipped; %llu "
        "keyframes; %llu re-initialisations; %llu weak directions overruled by the cameras\n",
        static_cast<unsigned long long>(f.scans_used),
        static_cast<unsigned long long>(f.scans_rejected),
        static_cast<unsigned long long>(f.scans_degenerate),
        static_cast<unsigned long long>(f.scans_skipped),
        static_cast<unsigned long long>(f.keyframes),
        static_cast<unsigned long long>(f.reinitialisations),
        static_cast<unsigned long long>(f.lidar_directions_overruled));
    std::printf("  IMU biases          gyro [%.5f %.5f %.5f] rad/s, accel [%.4f %.4f %.4f] m/s^2\n",
                f.gyro_bias_radps.x(), f.gyro_bias_radps.y(), f.gyro_bias_radps.z(),
                f.accel_bias_mps2.x(), f.accel_bias_mps2.y(), f.accel_bias_mps2.z());
  }
  if (!st.estimator.camera.mode.empty()) {
    const CameraFigures& c = st.estimator.camera;
    const double frames = static_cast<double>(std::max<std::uint64_t>(c.frames, 1));
    std::printf(
        "  camera front end    %s: %llu frames (%llu unusable, %llu without IMU), %.0f "
        "features/frame, match success %.1f %%, lidar depth for %.1f %% of features, %llu tracks "
        "dropped as fixed to the camera, %llu frozen thermal frames left out; mean confidence "
        "visible %.2f, thermal %.2f, fused %.2f\n",
        std::string(c.mode).c_str(), static_cast<unsigned long long>(c.frames),
        static_cast<unsigned long long>(c.frames_unusable),
        static_cast<unsigned long long>(c.frames_without_imu),
        static_cast<double>(c.features_total) / frames, 100.0 * c.match_success_rate(),
        c.features_total > 0
            ? 100.0 * static_cast<double>(c.depth_total) / static_cast<double>(c.features_total)
            : 0.0,
        static_cast<unsigned long long>(c.static_dropped_total),
        static_cast<unsigned long long>(c.thermal_frozen), c.mean_confidence[0],
        c.mean_confidence[1], c.mean_confidence[2]);
  }
  print_visual_summary(st.estimator);
  if (!publisher)
    std::printf("  published           nothing (offline run, no DDS)\n");
  else
    std::printf("  published           %llu odom, %llu pose, %llu status on DDS domain %d%s\n",
                static_cast<unsigned long long>(tally.odom.load()),
                static_cast<unsigned long long>(tally.pose),
                static_cast<unsigned long long>(tally.status), config.dds.domain_id,
                tally.failed.load() ? " (some writes failed)" : "");
  if (publisher) {
    std::printf("  latency             %s\n", odom_latency.line(live_clock).c_str());
    std::printf("                      %s\n", pose_latency.line(live_clock).c_str());
    const std::string_view mode = pipe.odometry_mode();
    std::printf("  odometry            %s\n",
                mode == "imu_thread"
                    ? "propagated on the IMU thread from the newest optimised state"
                : mode == "in_order"
                    ? "propagated from the optimised states in data order (max-speed replay)"
                    : "propagated by the back end after each measurement");
  }
  if (recorder) {
    const auto rc = recorder->counters();
    std::printf("  recorded            %llu messages to %s (%.1f MB, %llu dropped)\n",
                static_cast<unsigned long long>(rc.messages_written), options.record_path.c_str(),
                static_cast<double>(rc.bytes_on_disk) / 1e6,
                static_cast<unsigned long long>(rc.dropped));
  }
  if (!map_line.empty()) std::printf("  map                 %s\n", map_line.c_str());
  if (tally.last) {
    const NavState& s = *tally.last;
    std::printf("  final pose          x %.3f m, y %.3f m, z %.3f m, yaw %.1f deg\n",
                s.p_map_base_m.x(), s.p_map_base_m.y(), s.p_map_base_m.z(), yaw_deg(s.q_map_base));
    std::printf("  distance travelled  %.2f m\n", tally.distance_m);
    if (synthetic) {
      const auto truth = synthetic->motion().at(s.stamp - synthetic->motion_start());
      std::printf("  vs known motion     position error %.3f m, heading error %.2f deg\n",
                  (s.p_map_base_m - truth.p_map_base_m).norm(),
                  s.q_map_base.angularDistance(truth.q_map_base) * 180.0 / M_PI);
    }
  } else {
    std::printf("  final pose          none (the estimator never aligned: was the IMU static?)\n");
    exit_code = options.duration_s > 0 ? 0 : exit_code;
  }
  std::fflush(stdout);
  return exit_code;
}

}  // namespace posed
