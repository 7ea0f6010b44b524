#include "daemon/run_daemon.hpp"

#include <malloc.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>
#include <string_view>
#include <thread>
#include <vector>

#include "daemon/build_info.hpp"
#include "daemon/dds/initial_pose_reader.hpp"
#include "daemon/dds/publisher.hpp"
#include "daemon/extra_outputs.hpp"
#include "daemon/notify/sd_notify.hpp"
#include "daemon/notify/stage_watchdog.hpp"
#include "daemon/pipeline/camera_calibration.hpp"
#include "daemon/pipeline/camera_stage.hpp"
#include "daemon/pipeline/latency_histogram.hpp"
#include "daemon/pipeline/pipeline.hpp"
#include "daemon/pipeline/recording_tap.hpp"
#include "daemon/pipeline/source_factory.hpp"
#include "daemon/pose_sinks.hpp"
#include "daemon/run_summary.hpp"
#include "daemon/wall_clock_follower.hpp"
#include "drivers/camera/libusb_transport.hpp"
#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"
#include "drivers/recording/map_directory.hpp"
#include "drivers/recording/map_files.hpp"
#include "drivers/recording/mcap_replay_source.hpp"
#include "drivers/recording/recorder.hpp"

namespace posed {
namespace {

/// The config's dds.security as the participant takes it (the loader already refused half of it).
dds::DdsSecurityFiles dds_security_files(const config::DdsSecuritySection& s) {
  if (!s.enclave.empty()) return dds::DdsSecurityFiles::from_enclave(s.enclave);
  return {s.identity_ca,    s.certificate, s.private_key,
          s.permissions_ca, s.governance,  s.permissions};
}

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

/// Writes the mapping stage's keyframe map to `dir` (--save-map DIR).
bool save_map_directory(const pipeline::Pipeline& pipe, const std::string& dir, HostToWall to_wall,
                        std::string& line) {
  mapping::KeyframeMap map = pipe.built_map();
  if (map.keyframes.empty()) {
    line =
        "none (the mapping stage kept no keyframe: mapping.loop_closure off, no lidar scan "
        "matched, or localising on a prior map, which is not grown)";
    POSED_LOG_ERROR("--save-map %s: %s", dir.c_str(), line.c_str());
    return false;
  }
  // Keyframes carry the wall clock on disk, as poses and TUM files do.
  for (mapping::MapKeyframe& kf : map.keyframes) kf.stamp_ns = to_wall(HostTime{kf.stamp_ns}).ns;
  std::string error;
  if (!drivers::recording::write_map_directory(dir, map, error)) {
    POSED_LOG_ERROR("--save-map: %s", error.c_str());
    line = "failed: " + error;
    return false;
  }
  std::size_t points = 0, loops = 0;
  for (const mapping::MapKeyframe& kf : map.keyframes) points += kf.points_base.size();
  for (const mapping::PoseGraphEdge& e : map.edges) loops += e.loop ? 1 : 0;
  char buf[512];
  std::snprintf(buf, sizeof buf, "%zu keyframes, %zu points (%.2f m voxels), %zu loop edges to %s/",
                map.keyframes.size(), points, map.voxel_m, loops, dir.c_str());
  line = buf;
  return true;
}

/// Loads --map DIR; null (logged) when it cannot.
std::shared_ptr<const mapping::KeyframeMap> load_prior_map(const std::string& dir) {
  auto map = std::make_shared<mapping::KeyframeMap>();
  std::string error;
  if (!drivers::recording::read_map_directory(dir, *map, error)) {
    POSED_LOG_ERROR("--map %s: %s", dir.c_str(), error.c_str());
    return nullptr;
  }
  if (map->keyframes.empty()) {
    POSED_LOG_ERROR("--map %s: the map has no keyframes", dir.c_str());
    return nullptr;
  }
  std::size_t points = 0;
  for (const mapping::MapKeyframe& kf : map->keyframes) points += kf.points_base.size();
  POSED_LOG_INFO("localising on %s: %zu keyframes, %zu points", dir.c_str(), map->keyframes.size(),
                 points);
  return map;
}

/// An initial pose from rt/initialpose, if one waits, to the localiser: only in the map frame
/// (RViz's fixed frame must be the map's).
void take_initial_pose(dds::InitialPoseReader& reader, pipeline::Pipeline& pipe,
                       const std::string& map_frame) {
  const std::optional<dds::InitialPose> pose = reader.take_newest();
  if (!pose) return;
  const Eigen::Vector3d p = pose->T_frame_base.translation();
  if (pose->frame_id != map_frame) {
    POSED_LOG_WARN(
        "%s: initial pose in frame '%s' ignored: it must be in '%s' (set RViz's fixed "
        "frame to it)",
        reader.topic().c_str(), pose->frame_id.c_str(), map_frame.c_str());
    return;
  }
  const Eigen::Vector3d heading = pose->T_frame_base.rotation().col(0);
  POSED_LOG_NOTICE("%s: initial pose (%.2f, %.2f, %.2f) m, heading %.1f deg in %s",
                   reader.topic().c_str(), p.x(), p.y(), p.z(),
                   std::atan2(heading.y(), heading.x()) * 180.0 / M_PI, map_frame.c_str());
  pipe.set_initial_pose(pose->T_frame_base);
}

/// How far the next --loop pass is shifted past the start of the last one: the span every
/// stream together delivered, plus the IMU's last sample interval, so the stamps go on as if the
/// recording continued. Nullopt when the pass delivered nothing.
std::optional<Duration> next_pass_shift(
    const std::vector<const drivers::recording::McapReplaySource*>& replayers) {
  std::optional<std::int64_t> first_ns, last_ns;
  std::int64_t gap_ns = 0;
  for (const auto* r : replayers) {
    const auto span = r->delivered_span();
    if (span.messages == 0) continue;
    first_ns = first_ns ? std::min(*first_ns, span.first_log_ns) : span.first_log_ns;
    last_ns = last_ns ? std::max(*last_ns, span.last_log_ns) : span.last_log_ns;
    if (r->name() == "imu") gap_ns = span.last_gap_ns;
  }
  if (!first_ns) return std::nullopt;
  return Duration::from_ns(*last_ns - *first_ns + std::max<std::int64_t>(gap_ns, 1));
}

/// One line per --loop pass: where it ended and what the estimator held, so a pass unlike the
/// others (a divergence) shows.
void log_pass(std::uint64_t pass, const pipeline::Pipeline& pipe, const PoseSinks& sinks) {
  const pipeline::PipelineStatus st = pipe.status();
  const FusionFigures& f = st.estimator;
  char end[96] = "no pose";
  if (const auto& last = sinks.tally().last) {
    std::snprintf(end, sizeof end, "ended at (%.2f, %.2f, %.2f) m", last->p_map_base_m.x(),
                  last->p_map_base_m.y(), last->p_map_base_m.z());
  }
  char depth[64] = "";
  if (f.camera.features_total > 0) {
    std::snprintf(depth, sizeof depth, ", lidar depth for %.1f %% of features",
                  100.0 * static_cast<double>(f.camera.depth_total - f.camera.stereo_depth_total) /
                      static_cast<double>(f.camera.features_total));
  }
  POSED_LOG_INFO("--loop pass %llu: %s, accel bias %.3f m/s^2, %llu re-initialisations%s",
                 static_cast<unsigned long long>(pass), end, f.accel_bias_mps2.norm(),
                 static_cast<unsigned long long>(f.reinitialisations), depth);
}

constexpr std::string_view kPcd = ".pcd";

/// "X.pcd" (a name before the suffix): the PCD + TUM map files, not a map directory.
bool ends_with_pcd(const std::string& path) {
  return path.size() > kPcd.size() && path.ends_with(kPcd);
}

}  // namespace

bool is_map_directory_path(const std::string& map_path) { return !ends_with_pcd(map_path); }

std::string keyframes_path_for(const std::string& map_path) {
  const std::string stem =
      ends_with_pcd(map_path) ? map_path.substr(0, map_path.size() - kPcd.size()) : map_path;
  return stem + ".keyframes.tum";
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
  // Live stamps stay on the wall clock through its steps (an NTP correction after boot).
  WallClockFollower wall_clock(read_wall_minus_host);
  HostToWall to_wall = wall_clock.to_wall();
  const bool replaying = !options.replay.path.empty();
  const bool follow_wall_clock = !replaying || options.replay.live_stamps;

  dds::DdsConfig dds_config;
  dds_config.domain_id = static_cast<std::uint32_t>(config.dds.domain_id);
  dds_config.map_frame = config.dds.map_frame;
  dds_config.odom_frame = config.dds.odom_frame;
  dds_config.base_frame = config.dds.base_frame;
  dds_config.cyclonedds_xml_path = config.dds.cyclonedds_config;
  dds_config.initial_pose_topic = config.dds.initialpose_topic;
  dds_config.security = dds_security_files(config.dds.security);
  dds_config.tf = config.publish.tf;
  dds_config.path = config.publish.path;
  dds_config.cloud = config.publish.cloud;
  dds_config.map = config.publish.map;
  dds_config.image = config.publish.image;
  dds_config.diagnostics = config.publish.diagnostics;
  std::string error;
  std::unique_ptr<dds::Publisher> publisher;
  if (options.publish_dds) publisher = dds::Publisher::create(dds_config, error);
  if (options.publish_dds && !publisher) {
    POSED_LOG_ERROR("cannot start DDS: %s", error.c_str());
    return 1;
  }

  pipeline::BuiltSources built;
  std::string replay_streams;
  std::vector<const drivers::recording::McapReplaySource*> replayers;
  std::shared_ptr<drivers::recording::McapChunkCache> replay_chunks;
  if (replaying) {
    pipeline::ReplayOptions replay_options = options.replay;
    replay_options.depth = config.depth_camera.feature_depth;
    pipeline::ReplaySources replay = pipeline::make_replay_sources(replay_options, error);
    // Replayed stamps are the recording's host clock; its wall offset keeps the DDS stamps (and
    // so the ground truth of a simulated run) in the recorded time base.
    // With --live-stamps the stamps are this host's clock now, and so is the wall offset.
    if (replay.have_host_to_wall && !options.replay.live_stamps) to_wall = replay.host_to_wall;
    built = std::move(replay.built);
    replay_streams = replay.streams;
    replayers = std::move(replay.replayers);
    replay_chunks = replay.chunks;
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
  std::shared_ptr<const mapping::KeyframeMap> prior_map;
  if (!options.prior_map_dir.empty()) {
    prior_map = load_prior_map(options.prior_map_dir);
    if (!prior_map) return 1;
    built.sources.prior_map = prior_map;
  }
  // Localising: RViz's 2D Pose Estimate (rt/initialpose) says where the robot is.
  std::unique_ptr<dds::InitialPoseReader> initial_pose_reader;
  if (prior_map && publisher && !dds_config.initial_pose_topic.empty()) {
    initial_pose_reader = dds::InitialPoseReader::create(*publisher, dds_config, error);
    if (!initial_pose_reader) {
      // Not fatal: the map still localises by descriptor. A keystore made before posed read
      // rt/initialpose does not permit it.
      POSED_LOG_WARN(
          "%s not read: %s (with DDS Security: remake the keystore with posectl "
          "security init)",
          dds_config.initial_pose_topic.c_str(), error.c_str());
    }
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

  // Besides poses and status: the recording's and Foxglove's copies, clouds, the image.
  ExtraOutputs extra;
  const ExtraOutputsSetup extra_setup{&options.config_path, options.record_outputs,
                                      built.sources.lidar != nullptr,
                                      built.sources.camera(CameraStream::kVisible) != nullptr ||
                                          built.sources.camera(CameraStream::kThermal) != nullptr,
                                      to_wall};
  if (!extra.open(config, publisher.get(), recorder.get(), extra_setup, error)) {
    POSED_LOG_ERROR("%s", error.c_str());
    return 1;
  }

  // Stamps are this host's clock now live and in a replay with --live-stamps; otherwise a
  // recording's, and how late a message is cannot be told from them.
  PoseSinks sinks(config, publisher.get(), recorder.get(), to_wall, started,
                  !replaying || options.replay.live_stamps);
  sinks.static_transforms();
  pipeline::PipelineOutputs outputs;
  outputs.keep_map = !options.map_path.empty();
  outputs.scan_observer = extra.scan_observer();
  outputs.frontend_observer = extra.frontend_observer();
  outputs.on_odom = [&sinks](const NavState& s) { sinks.odom(s); };
  outputs.on_state = [&sinks](const NavState& s, const Eigen::Isometry3d& T_map_odom) {
    sinks.state(s, T_map_odom);
  };
  outputs.on_status = [&sinks](const pipeline::PipelineStatus& st) { sinks.status(st); };

  const bool built_has_lidar = built.sources.lidar != nullptr;
  // A replay at full speed can be over before discovery has matched a reader that was already
  // waiting for it (volatile durability: samples before the match are not delivered). Give such
  // readers a moment to match first; live data has no beginning worth waiting for.
  const double wait_s = options.wait_subscribers_s >= 0 ? options.wait_subscribers_s
                        : replaying                     ? 1.0
                                                        : 0.0;
  if (publisher && wait_s > 0) {
    const HostTime give_up = drivers::host_now() + Duration::from_seconds(wait_s);
    // A reader: a DDS reader of odom or pose, or a Foxglove client subscribed to either.
    while (publisher->matched_subscribers(dds::Topic::kOdom) == 0 &&
           publisher->matched_subscribers(dds::Topic::kPose) == 0 && !extra.foxglove_reader() &&
           drivers::host_now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  // A --loop replay runs pass after pass, each through a pipeline of its own: decoders, clock
  // sync and estimator start afresh as they did on the first pass, so no pass inherits the one
  // before it (the robot teleported back to the start). Its stamps go on increasing: each pass is
  // shifted to start one IMU period after the last one ended.
  std::unique_ptr<pipeline::Pipeline> pipe;
  notify::SdNotifier notifier;
  notify::StageWatchdog watchdog;
  std::vector<notify::StageWatchdog::StageId> watched;
  notify::WatchdogPinger pinger(notifier.watchdog_interval());
  const HostTime pipeline_started = drivers::host_now();
  int exit_code = 0;
  bool stopping = false;
  HostTime next_status_line = started + Duration::from_s(1);
  const timespec poll_period{0, 100'000'000};
  std::uint64_t passes = 0;
  Duration pass_shift = Duration::from_ns(0);
  HostTime pass_started = started;
  for (;;) {
    if (passes > 0) pass_started = drivers::host_now();
    pipe = std::make_unique<pipeline::Pipeline>(config, std::move(built.sources), outputs);
    if (!pipe->start(error)) {
      POSED_LOG_ERROR("cannot start the pipeline: %s", error.c_str());
      return 1;
    }
    if (passes == 0) {
      // Only the stages this pipeline runs are watched; a stage that never started cannot
      // stall. Every pass runs the same stages.
      for (const std::string& stage : pipe->stage_names()) {
        watched.push_back(watchdog.register_stage(
            stage, Duration::from_seconds(config.watchdog.stage_deadline_s), started));
      }
      notifier.notify("READY=1\nSTATUS=sources open, aligning");
      char dds_part[128] = "offline, no DDS";
      if (publisher) {
        std::snprintf(dds_part, sizeof dds_part,
                      "on DDS domain %d (rt/posed/odom, rt/posed/pose, rt/posed/status)",
                      config.dds.domain_id);
      }
      if (replaying) {
        POSED_LOG_INFO("replaying %s (%s) %s%s", options.replay.path.c_str(),
                       replay_streams.c_str(), dds_part,
                       options.replay.loop ? ", pass after pass (--loop)" : "");
      } else {
        POSED_LOG_INFO("running: imu %s%s %s", config.imu.source.c_str(),
                       config.lidar.enabled ? ", lidar" : "", dds_part);
      }
    }

    while (!pipe->finished()) {
      siginfo_t info{};
      const int sig = sigtimedwait(&signals, &info, &poll_period);
      const HostTime now = drivers::host_now();
      if (initial_pose_reader) take_initial_pose(*initial_pose_reader, *pipe, config.dds.map_frame);
      if (sig == SIGTERM || sig == SIGINT) {
        if (stopping) {
          POSED_LOG_ERROR("second %s: aborting without draining", strsignal(sig));
          std::_Exit(128 + sig);
        }
        POSED_LOG_INFO("%s: draining and stopping", strsignal(sig));
        notifier.notify("STOPPING=1\nSTATUS=draining");
        stopping = true;
        pipe->request_stop();
      } else if (sig == SIGHUP) {
        POSED_LOG_NOTICE("SIGHUP: no setting can be reloaded while running yet; restart to apply");
      }
      if (!stopping && !replaying && options.duration_s > 0 &&
          (now - started).seconds() >= options.duration_s) {
        POSED_LOG_INFO("--duration %.1f s reached: draining and stopping", options.duration_s);
        notifier.notify("STOPPING=1\nSTATUS=draining");
        stopping = true;
        pipe->request_stop();
      }
      if (follow_wall_clock) {
        if (const std::optional<Duration> step = wall_clock.poll()) {
          POSED_LOG_NOTICE(
              "wall clock stepped by %+.3f s: DDS stamps follow it (the monotonic clock, and so "
              "the estimate, did not move)",
              step->seconds());
        }
      }
      const std::vector<pipeline::StageBeat> beats = pipe->stage_heartbeats();
      for (std::size_t i = 0; i < watched.size() && i < beats.size(); ++i) {
        watchdog.heartbeat(watched[i], beats[i].last);
      }
      const std::string line = sinks.status_line();
      if (const auto message = pinger.poll(now, watchdog.check(now), line)) {
        notifier.notify(*message);
      }
      // While a stage stalls the pinger's STATUS= names it; ours would hide that.
      if (now >= next_status_line && !pinger.reporting_stall()) {
        next_status_line = now + Duration::from_s(1);
        notifier.notify("STATUS=" + line);
      }
    }
    pipe->join();
    ++passes;
    if (!replaying || !options.replay.loop) break;
    log_pass(passes, *pipe, sinks);
    if (stopping || (options.replay.max_passes > 0 && passes >= options.replay.max_passes)) break;
    const std::optional<Duration> next_shift = next_pass_shift(replayers);
    if (!next_shift) {
      POSED_LOG_WARN("--loop: pass %llu replayed nothing; stopping",
                     static_cast<unsigned long long>(passes));
      break;
    }
    pass_shift = pass_shift + *next_shift;
    pipeline::ReplayOptions next = options.replay;
    next.depth = config.depth_camera.feature_depth;
    next.time_shift = pass_shift;
    pipeline::ReplaySources replay = pipeline::make_replay_sources(next, error);
    if (!replay.built.sources.imu) {
      POSED_LOG_ERROR("--loop pass %llu: %s", static_cast<unsigned long long>(passes + 1),
                      error.c_str());
      exit_code = 1;
      break;
    }
    replay.built.sources.prior_map = prior_map;
    // The last pass's pipeline, with its Sources, goes before the next one is built, and the
    // heap it freed goes back to the system: glibc keeps freed memory in its arenas, and the
    // next pass's threads and allocations rarely fit the same holes, so without the trim
    // resident memory grows every pass although nothing leaks (heaptrack: the heap in use peaks
    // alike in every pass). 30 passes of a 10 s recording: heap and stacks +65 MB without the
    // trim, +23 MB with it (docs/faults.md).
    // The last pass's chunk cache goes with it, before the trim (its 32 decompressed chunks were
    // freed after the trim, and stayed resident in the heap through the next pass).
    replay_chunks.reset();
    pipe.reset();
    ::malloc_trim(0);
    built = std::move(replay.built);
    replayers = std::move(replay.replayers);
    replay_chunks = replay.chunks;
    if (recorder) pipeline::tap_sources(built.sources, *recorder, config);
    sinks.new_pass();
  }
  // The loop-closed trajectory as it stands at the end (the last pass's): every keyframe's
  // optimised pose, for evaluating the map rather than the poses as they went out.
  if (recorder && pipe) {
    for (const auto& [stamp, T] : pipe->optimised_keyframes()) {
      const Eigen::Quaterniond q(T.rotation());
      const Eigen::Vector3d& p = T.translation();
      recorder->write_pose("/posed/keyframes", to_wall(stamp), config.dds.map_frame,
                           {p.x(), p.y(), p.z()}, {q.x(), q.y(), q.z(), q.w()});
    }
  }
  extra.stop();  // the last clouds and images reach the recording too
  if (recorder && !recorder->close()) {
    POSED_LOG_ERROR("recording %s: %s", options.record_path.c_str(), recorder->error().c_str());
    exit_code = 1;
  }
  std::string map_line;
  if (!options.map_path.empty() && !save_map(*pipe, options.map_path, to_wall, map_line))
    exit_code = 1;
  if (!options.map_dir.empty()) {
    std::string dir_line;
    if (!save_map_directory(*pipe, options.map_dir, to_wall, dir_line)) exit_code = 1;
    map_line += (map_line.empty() ? "" : "; ") + dir_line;
  }

  const RunSummary summary{config,         options,          *pipe,
                           sinks,          started,          pipeline_started,
                           replay_streams, built_has_lidar,  recorder.get(),
                           map_line,       synthetic,        publisher != nullptr,
                           extra.clouds(), extra.foxglove(), extra.images(),
                           passes,         pass_started,     replay_chunks.get()};
  // A timed run that never aligned is not a failure of the run itself.
  if (!print_run_summary(summary) && options.duration_s > 0) exit_code = 0;
  return exit_code;
}

}  // namespace posed
