#include "daemon/pose_sinks.hpp"

#include <cstdio>

#include "daemon/build_info.hpp"
#include "daemon/dds/publisher.hpp"
#include "drivers/common/host_clock.hpp"
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

}  // namespace

void PoseSinks::static_transforms() {
  if (!publisher_ || !config_.publish.tf) return;
  // A replay's messages carry the recording's time: the transforms wait for its first state,
  // so a recording of the outputs (and Foxglove's timeline) has them where the data starts.
  if (!live_clock_) {
    static_pending_ = true;
    return;
  }
  publish_static_transforms(drivers::wall_now());
}

void PoseSinks::publish_static_transforms(WallTime stamp) {
  static_pending_ = false;
  if (!publisher_->publish_tf_static(posed::static_transforms(config_, stamp))) {
    tally_.failed.fetch_add(1, std::memory_order_relaxed);
  }
}

void PoseSinks::ros_outputs(const NavState& s, const Eigen::Isometry3d& T_map_odom,
                            const dds::PoseMessage& pose) {
  if (!publisher_) return;
  if (config_.publish.tf && (config_.publish.tf_max_rate_hz <= 0 || s.stamp >= next_tf_stamp_)) {
    if (config_.publish.tf_max_rate_hz > 0) {
      next_tf_stamp_ = s.stamp + Duration::from_seconds(1.0 / config_.publish.tf_max_rate_hz);
    }
    if (!publisher_->publish_tf(tf_tree(config_.dds, s, T_map_odom, pose.stamp))) {
      tally_.failed.fetch_add(1, std::memory_order_relaxed);
    }
  }
  if (config_.publish.path) {
    path_.add(pose);
    if (s.stamp >= next_path_stamp_) {
      next_path_stamp_ = s.stamp + Duration::from_seconds(1.0 / config_.publish.path_rate_hz);
      if (!publisher_->publish_path(path_.path())) {
        tally_.failed.fetch_add(1, std::memory_order_relaxed);
      }
    }
  }
}

PoseSinks::PoseSinks(const config::PosedConfig& config, dds::Publisher* publisher,
                     drivers::recording::Recorder* recorder, HostToWall to_wall, HostTime started,
                     bool live_clock)
    : config_(config),
      publisher_(publisher),
      recorder_(recorder),
      to_wall_(to_wall),
      started_(started),
      live_clock_(live_clock),
      pose_period_(Duration::from_seconds(1.0 / config.publish.pose_rate_hz)),
      path_(config.publish.path_min_step_m,
            static_cast<std::size_t>(config.publish.path_max_poses)) {}

void PoseSinks::new_pass() {
  pass_start_ = true;
  // Until the new estimator's first optimised state, its propagation is decimated onto pose,
  // as on the first pass.
  tally_.have_optimised = false;
  tally_.last_pose_stamp.reset();
  path_.clear();
}

void PoseSinks::odom(const NavState& s) {
  if (tally_.last && !pass_start_) {
    tally_.distance_m += (s.p_map_base_m - tally_.last->p_map_base_m).norm();
  }
  pass_start_ = false;
  if (!tally_.first) tally_.first = s;
  tally_.last = s;
  if (odom_index_++ % static_cast<std::uint64_t>(config_.publish.odom_decimation) != 0) return;
  const WallTime stamp = to_wall_(s.stamp);
  if (publisher_) {
    dds::OdomMessage odom;
    odom.stamp = stamp;
    odom.p_map_base_m = s.p_map_base_m;
    odom.q_map_base = s.q_map_base;
    odom.v_base_mps = s.q_map_base.conjugate() * s.v_map_mps;
    odom.w_base_radps = s.w_base_radps;
    odom.pose_covariance = to_row_major(s.pose_covariance);
    odom.twist_covariance = to_row_major(s.twist_covariance);
    if (publisher_->publish_odom(odom)) {
      odom_latency_.record(s, drivers::host_now());
      tally_.odom.fetch_add(1, std::memory_order_relaxed);
    } else {
      tally_.failed.fetch_add(1, std::memory_order_relaxed);
    }
  }
  if (recorder_) {
    // After the write: the recording must never delay the odometry.
    const Eigen::Quaterniond& q = s.q_map_base;
    const Eigen::Vector3d v_base = s.q_map_base.conjugate() * s.v_map_mps;
    recorder_->write_odometry("/posed/odom", stamp, config_.dds.odom_frame, config_.dds.base_frame,
                              {s.p_map_base_m.x(), s.p_map_base_m.y(), s.p_map_base_m.z()},
                              {q.x(), q.y(), q.z(), q.w()}, {v_base.x(), v_base.y(), v_base.z()},
                              {s.w_base_radps.x(), s.w_base_radps.y(), s.w_base_radps.z()});
  }
}

void PoseSinks::state(const NavState& s, const Eigen::Isometry3d& T_map_odom) {
  const WallTime stamp = to_wall_(s.stamp);
  newest_state_stamp_ = s.stamp;
  if (static_pending_) publish_static_transforms(stamp);
  // Optimised states (one per scan) go on rt/posed/pose; IMU propagation (when the back end
  // makes it) on rt/posed/odom. An estimator without optimised states (strapdown) has its
  // propagation decimated onto pose.
  if (s.optimised) tally_.have_optimised = true;
  if (!s.optimised) odom(s);
  bool pose_now = s.optimised || (!tally_.have_optimised && s.stamp >= tally_.next_pose_stamp);
  if (pose_now && tally_.last_pose_stamp && s.stamp <= *tally_.last_pose_stamp) {
    pose_now = false;
    ++tally_.pose_out_of_order;
  }
  if (pose_now) {
    tally_.next_pose_stamp = s.stamp + pose_period_;
    tally_.last_pose_stamp = s.stamp;
    // The state is in the odometry frame (the estimator's); the pose goes out in map.
    dds::PoseMessage pose;
    pose.stamp = stamp;
    pose.p_map_base_m = T_map_odom * s.p_map_base_m;
    pose.q_map_base = Eigen::Quaterniond(T_map_odom.rotation()) * s.q_map_base;
    if (!publisher_) {
      // offline run: nothing to publish
    } else if (publisher_->publish_pose(pose)) {
      pose_latency_.record(s, drivers::host_now());
      ++tally_.pose;
    } else {
      tally_.failed.fetch_add(1, std::memory_order_relaxed);
    }
    ros_outputs(s, T_map_odom, pose);
    if (recorder_) {
      const Eigen::Quaterniond& q = pose.q_map_base;
      const Eigen::Vector3d& p = pose.p_map_base_m;
      recorder_->write_pose("/posed/pose", stamp, config_.dds.map_frame, {p.x(), p.y(), p.z()},
                            {q.x(), q.y(), q.z(), q.w()});
    }
  }
}

void PoseSinks::status(const pipeline::PipelineStatus& st) {
  dds::StatusMessage msg;
  // Live, the report's own time; in a replay the data's (the newest state), so the status sits
  // with the poses it describes, not decades away from them.
  msg.stamp = live_clock_ ? to_wall_(st.stamp) : to_wall_(newest_state_stamp_.value_or(st.stamp));
  const bool publish = live_clock_ || newest_state_stamp_.has_value();
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
                     v.residual_median,
                     v.keyframe_factors,
                     v.still};
  }
  msg.selection = {f.selection.lidar_visual_inertial, f.selection.lidar_inertial,
                   f.selection.visual_inertial, f.selection.imu_only, f.selection.last_threshold_m};
  msg.uptime_s = (st.stamp - started_).seconds();
  msg.latency = {odom_latency_.message(live_clock_), pose_latency_.message(live_clock_)};
  if (st.mapping) {  // else "off"
    const pipeline::MappingStatus& m = *st.mapping;
    msg.mapping = {m.state, m.keyframes, m.loops, m.fixes, m.correction_m, m.scans_skipped};
  }
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
  if (!st.imu_in_use.empty()) {
    // Which IMU the estimate runs on, when the D435i's is there as the A9's backup.
    char part[96];
    std::snprintf(part, sizeof part, "; imu on %s (%llu failovers)", st.imu_in_use.c_str(),
                  static_cast<unsigned long long>(st.imu_failovers));
    line += part;
  }
  char odom_part[96];
  if (live_clock_ && odom_latency_.receive_to_write.count() > 0) {
    std::snprintf(odom_part, sizeof odom_part, "; %llu odom published, p99 %.2f ms late",
                  static_cast<unsigned long long>(tally_.odom.load()),
                  static_cast<double>(odom_latency_.receive_to_write.percentile_ns(0.99)) * 1e-6);
  } else {
    std::snprintf(odom_part, sizeof odom_part, "; %llu odom published",
                  static_cast<unsigned long long>(tally_.odom.load()));
  }
  line += odom_part;
  msg.summary = line;
  if (!publisher_ || !publish) {
    // offline run, or a replay before its first state: nothing to publish
  } else if (publisher_->publish_status(msg)) {
    ++tally_.status;
  } else {
    tally_.failed.fetch_add(1, std::memory_order_relaxed);
  }
  if (publisher_ && publish && config_.publish.diagnostics &&
      !publisher_->publish_diagnostics(diagnostics(st, msg.stamp))) {
    tally_.failed.fetch_add(1, std::memory_order_relaxed);
  }
  std::lock_guard lock(status_line_mutex_);
  status_line_ = line;
}

std::string PoseSinks::status_line() const {
  std::lock_guard lock(status_line_mutex_);
  return status_line_;
}

}  // namespace posed
