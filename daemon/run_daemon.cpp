#include "daemon/run_daemon.hpp"

#include <signal.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <optional>

#include "daemon/build_info.hpp"
#include "daemon/dds/publisher.hpp"
#include "daemon/notify/sd_notify.hpp"
#include "daemon/notify/stage_watchdog.hpp"
#include "daemon/pipeline/pipeline.hpp"
#include "daemon/pipeline/source_factory.hpp"
#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"

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

/// What the publisher thread has seen, for the summary (read by main after the threads end).
struct PublishTally {
  std::uint64_t odom = 0;
  std::uint64_t pose = 0;
  std::uint64_t status = 0;
  std::uint64_t failed = 0;
  std::optional<NavState> first;
  std::optional<NavState> last;
  double distance_m = 0;
  HostTime next_pose_stamp;
};

}  // namespace

int run_daemon(const config::PosedConfig& config, const RunOptions& options) {
  // Signals are taken synchronously by this thread; the stage threads inherit the mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  const HostTime started = drivers::host_now();
  const HostToWall to_wall{drivers::wall_now() - WallTime::from_ns(started.ns)};

  dds::DdsConfig dds_config;
  dds_config.domain_id = static_cast<std::uint32_t>(config.dds.domain_id);
  dds_config.map_frame = config.dds.map_frame;
  dds_config.base_frame = config.dds.base_frame;
  dds_config.cyclonedds_xml_path = config.dds.cyclonedds_config;
  std::string error;
  std::unique_ptr<dds::Publisher> publisher = dds::Publisher::create(dds_config, error);
  if (!publisher) {
    POSED_LOG_ERROR("cannot start DDS: %s", error.c_str());
    return 1;
  }

  pipeline::BuiltSources built = pipeline::make_sources(config, error);
  if (!built.sources.imu) {
    POSED_LOG_ERROR("%s", error.c_str());
    return 1;
  }
  // Owned by the pipeline, which outlives every use below.
  const drivers::SyntheticImuSource* synthetic = built.synthetic;

  PublishTally tally;
  const Duration pose_period = Duration::from_seconds(1.0 / config.publish.pose_rate_hz);
  std::uint64_t state_index = 0;
  pipeline::PipelineOutputs outputs;
  outputs.on_state = [&](const NavState& s) {
    if (tally.last) tally.distance_m += (s.p_map_base_m - tally.last->p_map_base_m).norm();
    if (!tally.first) tally.first = s;
    tally.last = s;
    const WallTime stamp = to_wall(s.stamp);
    if (state_index++ % static_cast<std::uint64_t>(config.publish.odom_decimation) == 0) {
      dds::OdomMessage odom;
      odom.stamp = stamp;
      odom.p_map_base_m = s.p_map_base_m;
      odom.q_map_base = s.q_map_base;
      odom.v_base_mps = s.q_map_base.conjugate() * s.v_map_mps;
      odom.w_base_radps = s.w_base_radps;
      odom.pose_covariance = to_row_major(s.pose_covariance);
      odom.twist_covariance = to_row_major(s.twist_covariance);
      if (publisher->publish_odom(odom))
        ++tally.odom;
      else
        ++tally.failed;
    }
    if (s.stamp >= tally.next_pose_stamp) {
      tally.next_pose_stamp = s.stamp + pose_period;
      dds::PoseMessage pose;
      pose.stamp = stamp;
      pose.p_map_base_m = s.p_map_base_m;
      pose.q_map_base = s.q_map_base;
      if (publisher->publish_pose(pose))
        ++tally.pose;
      else
        ++tally.failed;
    }
  };
  std::mutex status_line_mutex;
  std::string status_line = "starting";
  outputs.on_status = [&](const pipeline::PipelineStatus& st) {
    dds::StatusMessage msg;
    msg.stamp = to_wall(st.stamp);
    msg.version = std::string(version_string());
    msg.estimator_mode = std::string(to_string(st.mode));
    msg.uptime_s = (st.stamp - started).seconds();
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
                  static_cast<unsigned long long>(tally.odom));
    line += odom_part;
    msg.summary = line;
    if (publisher->publish_status(msg))
      ++tally.status;
    else
      ++tally.failed;
    std::lock_guard lock(status_line_mutex);
    status_line = line;
  };

  pipeline::Pipeline pipe(config, std::move(built.sources), std::move(outputs));
  if (!pipe.start(error)) {
    POSED_LOG_ERROR("cannot start the pipeline: %s", error.c_str());
    return 1;
  }

  notify::SdNotifier notifier;
  notify::StageWatchdog watchdog;
  // Only the stages this pipeline runs are watched; a stage that never started cannot stall.
  std::vector<std::pair<pipeline::Stage, notify::StageWatchdog::StageId>> watched;
  for (const pipeline::Stage stage : pipe.active_stages()) {
    watched.emplace_back(
        stage,
        watchdog.register_stage(std::string(pipeline::kStageNames[static_cast<std::size_t>(stage)]),
                                Duration::from_seconds(config.watchdog.stage_deadline_s), started));
  }
  notify::WatchdogPinger pinger(notifier.watchdog_interval());
  notifier.notify("READY=1\nSTATUS=sources open, aligning");
  POSED_LOG_INFO("running: %s on DDS domain %d (rt/posed/odom, rt/posed/pose, rt/posed/status)",
                 config.imu.source.c_str(), config.dds.domain_id);

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
    if (!stopping && options.duration_s > 0 && (now - started).seconds() >= options.duration_s) {
      POSED_LOG_INFO("--duration %.1f s reached: draining and stopping", options.duration_s);
      notifier.notify("STOPPING=1\nSTATUS=draining");
      stopping = true;
      pipe.request_stop();
    }
    const auto beats = pipe.stage_heartbeats();
    for (const auto& [stage, id] : watched) {
      watchdog.heartbeat(id, beats[static_cast<std::size_t>(stage)]);
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

  // The summary a person reads at the end of a run.
  const pipeline::PipelineStatus st = pipe.status();
  const double run_s = (drivers::host_now() - started).seconds();
  std::printf("\nposed summary\n");
  std::printf("  run time            %.1f s\n", run_s);
  std::printf("  estimator           %s (IMU-only dead reckoning: drifts without aiding)\n",
              std::string(to_string(st.mode)).c_str());
  for (const auto& s : st.streams) {
    std::printf(
        "  %-19s %llu decoded (%.1f Hz mean), %llu malformed, %llu dropped; clock %s, "
        "offset %.3f ms, drift %.1f ppm\n",
        s.name.c_str(), static_cast<unsigned long long>(s.decoded),
        run_s > 0 ? static_cast<double>(s.decoded) / run_s : 0.0,
        static_cast<unsigned long long>(s.malformed), static_cast<unsigned long long>(s.dropped),
        s.clock_state.c_str(), static_cast<double>(s.clock_offset_ns) * 1e-6, s.clock_drift_ppm);
  }
  if (config.lidar.enabled) {
    std::printf(
        "  lidar scans         %llu assembled (%.0f points/scan mean), %llu reached the "
        "fusion core (not used by the strapdown estimator)\n",
        static_cast<unsigned long long>(st.lidar_scans),
        st.lidar_scans ? static_cast<double>(st.lidar_points) / static_cast<double>(st.lidar_scans)
                       : 0.0,
        static_cast<unsigned long long>(st.lidar_scans_fused));
  }
  std::printf("  published           %llu odom, %llu pose, %llu status on DDS domain %d%s\n",
              static_cast<unsigned long long>(tally.odom),
              static_cast<unsigned long long>(tally.pose),
              static_cast<unsigned long long>(tally.status), config.dds.domain_id,
              tally.failed ? " (some writes failed)" : "");
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
