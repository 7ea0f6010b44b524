#include "daemon/run_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "daemon/cloud_output.hpp"
#include "daemon/estimator_summary.hpp"
#include "daemon/foxglove/server.hpp"
#include "daemon/image_output.hpp"
#include "daemon/pipeline/pipeline.hpp"
#include "daemon/resident_memory.hpp"
#include "drivers/common/host_clock.hpp"
#include "drivers/recording/mcap_chunk_cache.hpp"
#include "drivers/recording/recorder.hpp"
#include "drivers/synthetic/synthetic_imu_source.hpp"

namespace posed {
namespace {

double yaw_deg(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x()) * 180.0 / M_PI;
}

/// `part` as a share of `whole` [%]; 0 when there is no whole.
double percent(std::uint64_t part, std::uint64_t whole) {
  return whole > 0 ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0;
}

}  // namespace

namespace {

/// The mapping stage's line: loops closed, candidates refused and why, the correction, the cost.
/// The localiser's line (posed --map): where it ended, how soon the first fix came, how it
/// tracked.
void print_localisation_summary(const pipeline::MappingFigures& m, const HostToWall& to_wall) {
  const mapping::LocalisationFigures& f = m.localisation;
  char first_fix[128] = "no fix";
  if (f.first_fix && f.first_scan) {
    // The stamp as posed's poses carry it, so evaluations can tell which were localised.
    std::snprintf(first_fix, sizeof first_fix, "first fix after %.2f s of data (at %.3f s)",
                  static_cast<double>(f.first_fix->ns - f.first_scan->ns) * 1e-9,
                  to_wall(*f.first_fix).seconds());
  }
  const auto refused = [&](mapping::RegistrationVerdict v) {
    return static_cast<unsigned long long>(f.rejected[static_cast<std::size_t>(v)]);
  };
  const std::uint64_t registrations =
      f.fixes + f.rejected[1] + f.rejected[2] + f.rejected[3] + f.rejected[4] + f.rejected[5];
  std::printf(
      "  localisation        %s; %s; %llu fixes over %llu tracking attempts and %llu lookups; "
      "lost %llu times\n",
      std::string(mapping::state_name(m.state)).c_str(), first_fix,
      static_cast<unsigned long long>(f.fixes), static_cast<unsigned long long>(f.track_attempts),
      static_cast<unsigned long long>(f.lookups), static_cast<unsigned long long>(f.times_lost));
  std::printf(
      "                      refused: %llu degenerate, %llu not close, %llu low overlap, %llu "
      "diverged, %llu unconfirmed, %llu off the map; registered in %.1f ms on average; map -> "
      "odom %.3f m, %.2f deg%s\n",
      refused(mapping::RegistrationVerdict::kDegenerate),
      refused(mapping::RegistrationVerdict::kNotClose),
      refused(mapping::RegistrationVerdict::kLowOverlap),
      refused(mapping::RegistrationVerdict::kDiverged),
      static_cast<unsigned long long>(f.unconfirmed), static_cast<unsigned long long>(f.off_map),
      registrations > 0 ? 1e3 * f.registration_time_s / static_cast<double>(registrations) : 0.0,
      m.T_map_odom.translation().norm(),
      Eigen::AngleAxisd(m.T_map_odom.rotation()).angle() * 180.0 / M_PI,
      m.keyframes_dropped > 0 ? " (some scans skipped: the mapping thread fell behind)" : "");
}

void print_mapping_summary(const pipeline::MappingFigures& m, const HostToWall& to_wall) {
  if (m.localising) {
    print_localisation_summary(m, to_wall);
    return;
  }
  const mapping::LoopClosureFigures& f = m.loops;
  std::uint64_t by_descriptor = 0;
  for (const mapping::LoopRecord& loop : m.accepted) by_descriptor += loop.by_descriptor ? 1 : 0;
  const auto refused = [&](mapping::RegistrationVerdict v) {
    return static_cast<unsigned long long>(f.rejected[static_cast<std::size_t>(v)]);
  };
  std::printf(
      "  loops               %llu closed (%llu by descriptor) over %llu keyframes; refused: %llu "
      "degenerate, %llu not close, %llu low overlap, %llu diverged, %llu unconfirmed, %llu "
      "implausible\n",
      static_cast<unsigned long long>(f.loops), static_cast<unsigned long long>(by_descriptor),
      static_cast<unsigned long long>(f.keyframes),
      refused(mapping::RegistrationVerdict::kDegenerate),
      refused(mapping::RegistrationVerdict::kNotClose),
      refused(mapping::RegistrationVerdict::kLowOverlap),
      refused(mapping::RegistrationVerdict::kDiverged),
      static_cast<unsigned long long>(f.unconfirmed),
      static_cast<unsigned long long>(f.implausible));
  const std::uint64_t registrations = f.distance_candidates + f.descriptor_candidates;
  std::printf(
      "                      candidates %llu by distance, %llu by descriptor, registered in "
      "%.1f ms on average; map -> odom %.3f m, %.2f deg; last optimisation %.3f s; keyframe "
      "clouds %.1f M points (%.1f MB; %llu keyframes left theirs to a mapped place)%s\n",
      static_cast<unsigned long long>(f.distance_candidates),
      static_cast<unsigned long long>(f.descriptor_candidates),
      registrations > 0 ? 1e3 * f.registration_time_s / static_cast<double>(registrations) : 0.0,
      m.T_map_odom.translation().norm(),
      Eigen::AngleAxisd(m.T_map_odom.rotation()).angle() * 180.0 / M_PI, f.last_optimisation_s,
      static_cast<double>(f.stored_points) / 1e6, static_cast<double>(f.stored_bytes) / 1e6,
      static_cast<unsigned long long>(f.mapped_keyframes),
      m.keyframes_dropped > 0 ? " (some keyframes dropped: the mapping thread fell behind)" : "");
}

}  // namespace

bool print_run_summary(const RunSummary& r) {
  const PublishTally& tally = r.sinks.tally();
  const pipeline::PipelineStatus st = r.pipe.status();
  const double run_s = (drivers::host_now() - r.started).seconds();
  std::printf("\nposed summary\n");
  std::printf("  run time            %.1f s\n", run_s);
  if (const ResidentMemory mem = read_resident_memory(); mem.peak_mb >= 0) {
    std::printf("  memory              peak resident %.1f MB; heap and stacks %.1f MB at the end\n",
                mem.peak_mb, mem.anon_mb);
  }
  std::printf("  estimator           %s, last mode %s\n", r.pipe.estimator_description().c_str(),
              std::string(to_string(st.mode)).c_str());
  // The stream counts are the last --loop pass's: their rates are over its time.
  const double streams_s = (drivers::host_now() - r.last_pass_started).seconds();
  for (const auto& s : st.streams) {
    // Chunks nothing could decode are a configuration problem, not damaged data: said apart.
    char undecodable[80] = "";
    if (s.undecodable > 0) {
      std::snprintf(undecodable, sizeof undecodable, " (%llu with no decoder configured)",
                    static_cast<unsigned long long>(s.undecodable));
    }
    // Refused chunks (another sender, oversized) never reached a decoder: said apart too.
    char refused[64] = "";
    if (s.refused > 0) {
      std::snprintf(refused, sizeof refused, ", %llu refused (wrong sender or size)",
                    static_cast<unsigned long long>(s.refused));
    }
    std::printf(
        "  %-19s %llu decoded (%.1f Hz mean), %llu malformed%s%s, %llu dropped; clock %s, "
        "offset %.3f ms, drift %.1f ppm\n",
        s.name.c_str(), static_cast<unsigned long long>(s.decoded),
        streams_s > 0 ? static_cast<double>(s.decoded) / streams_s : 0.0,
        static_cast<unsigned long long>(s.malformed), undecodable, refused,
        static_cast<unsigned long long>(s.dropped), s.clock_state.c_str(),
        static_cast<double>(s.clock_offset_ns) * 1e-6, s.clock_drift_ppm);
  }
  if (!st.imu_in_use.empty()) {
    std::printf(
        "  imu failover        %llu time(s) to the D435i's IMU, %llu of its samples used; "
        "on the %s at the end\n",
        static_cast<unsigned long long>(st.imu_failovers),
        static_cast<unsigned long long>(st.imu_backup_used),
        st.imu_in_use == "a9" ? "A9" : "D435i's IMU");
  }
  if (!r.options.replay.path.empty()) {
    std::printf("  replayed            %s (%s)\n", r.options.replay.path.c_str(),
                r.replay_streams.c_str());
    if (r.replay_chunks != nullptr) {
      const drivers::recording::McapChunkCacheCounters c = r.replay_chunks->counters();
      const std::uint64_t reads = c.hits + c.misses;
      std::printf(
          "  replay reading      %llu compressed chunks decompressed, %llu reads served from "
          "another stream's (%.1f %%)\n",
          static_cast<unsigned long long>(c.misses), static_cast<unsigned long long>(c.hits),
          percent(c.hits, reads));
    }
    if (r.options.replay.loop) {
      std::printf(
          "  passes              %llu, each from a fresh start (decoders, clock sync, "
          "estimator); the stream and estimator figures are the last pass's\n",
          static_cast<unsigned long long>(r.passes));
    }
    // What a replay costs: the span of data turned into poses per second of wall time.
    const double processing_s = (drivers::host_now() - r.pipeline_started).seconds();
    if (tally.first && tally.last && processing_s > 0) {
      const double span_s = (tally.last->stamp - tally.first->stamp).seconds();
      std::printf("  real-time factor    %.2fx (%.1f s of data in %.1f s)\n", span_s / processing_s,
                  span_s, processing_s);
    }
  }
  {
    // Most items ever waiting in each queue between the stages, against its capacity: a queue
    // that filled is a stage that fell behind (at --max-speed the stages are the pace, and
    // every queue fills by design).
    std::string line;
    std::uint64_t dropped = 0;
    for (const pipeline::NamedQueueCounters& q : r.pipe.queue_counters()) {
      line += (line.empty() ? "" : ", ") + q.name + " " + std::to_string(q.counters.high_water) +
              "/" + std::to_string(q.counters.capacity);
      dropped += q.counters.dropped();
    }
    std::printf("  queues              most waiting/capacity: %s; %llu dropped\n", line.c_str(),
                static_cast<unsigned long long>(dropped));
  }
  if (r.has_lidar) {
    // Scans left out before the fusion core, said only when there were any: a scan open when
    // the lidar fell silent (stale), or stamped a second or more from its arrival (corrupt time).
    std::string left_out;
    if (st.lidar_scans_cut_by_silence + st.lidar_scans_implausible > 0) {
      left_out = "; left out: " + std::to_string(st.lidar_scans_cut_by_silence) +
                 " open when the data stopped, " + std::to_string(st.lidar_scans_implausible) +
                 " stamped implausibly";
    }
    std::printf(
        "  lidar scans         %llu assembled (%.0f points/scan mean), %llu reached the "
        "fusion core, %llu used by the estimator%s\n",
        static_cast<unsigned long long>(st.lidar_scans),
        st.lidar_scans ? static_cast<double>(st.lidar_points) / static_cast<double>(st.lidar_scans)
                       : 0.0,
        static_cast<unsigned long long>(st.lidar_scans_fused),
        static_cast<unsigned long long>(st.estimator.scans_used), left_out.c_str());
  }
  if (r.has_lidar) {
    const FusionFigures& f = st.estimator;
    std::printf(
        "  scan matching       %llu used, %llu rejected, %llu degenerate, %llu skipped; %llu "
        "keyframes; %llu re-initialisations; %llu weak directions overruled by the cameras, %llu "
        "left to the IMU while the cameras were blind; %llu states held to the vehicle's motion\n",
        static_cast<unsigned long long>(f.scans_used),
        static_cast<unsigned long long>(f.scans_rejected),
        static_cast<unsigned long long>(f.scans_degenerate),
        static_cast<unsigned long long>(f.scans_skipped),
        static_cast<unsigned long long>(f.keyframes),
        static_cast<unsigned long long>(f.reinitialisations),
        static_cast<unsigned long long>(f.lidar_directions_overruled),
        static_cast<unsigned long long>(f.lidar_directions_left_to_imu),
        static_cast<unsigned long long>(f.vehicle_motion_states));
    std::printf("  IMU biases          gyro [%.5f %.5f %.5f] rad/s, accel [%.4f %.4f %.4f] m/s^2\n",
                f.gyro_bias_radps.x(), f.gyro_bias_radps.y(), f.gyro_bias_radps.z(),
                f.accel_bias_mps2.x(), f.accel_bias_mps2.y(), f.accel_bias_mps2.z());
    if (f.gravity_tilt_estimated) {
      std::printf(
          "  map tilt            %.3f deg about x, %.3f deg about y (gravity's direction in "
          "the map; headings spanned where the lidar pinned the position %.0f deg; free in "
          "%.1f %% of the window's solves, held before)\n",
          f.gravity_tilt_rad.x() * 180.0 / M_PI, f.gravity_tilt_rad.y() * 180.0 / M_PI,
          f.heading_span_rad * 180.0 / M_PI,
          100.0 * static_cast<double>(f.window_solves_tilt_free) /
              static_cast<double>(std::max<std::uint64_t>(f.window_solves, 1)));
    }
  }
  if (!st.estimator.camera.mode.empty()) {
    const CameraFigures& c = st.estimator.camera;
    const double frames = static_cast<double>(std::max<std::uint64_t>(c.frames, 1));
    // The D435i's depth node, where a recording or the rig has one.
    char stereo[128] = "";
    if (c.depth_images > 0) {
      std::snprintf(stereo, sizeof stereo,
                    ", depth-image depth for %.1f %% more (%llu frames given a depth image)",
                    percent(c.stereo_depth_total, c.features_total),
                    static_cast<unsigned long long>(c.depth_images));
    }
    std::printf(
        "  camera front end    %s: %llu frames (%llu unusable, %llu without IMU), %.0f "
        "features/frame, match success %.1f %%, lidar depth for %.1f %% of features%s, %llu "
        "tracks dropped as fixed to the camera, %llu frozen thermal frames left out; mean "
        "confidence visible %.2f, thermal %.2f, fused %.2f\n",
        std::string(c.mode).c_str(), static_cast<unsigned long long>(c.frames),
        static_cast<unsigned long long>(c.frames_unusable),
        static_cast<unsigned long long>(c.frames_without_imu),
        static_cast<double>(c.features_total) / frames, 100.0 * c.match_success_rate(),
        percent(c.depth_total - c.stereo_depth_total, c.features_total), stereo,
        static_cast<unsigned long long>(c.static_dropped_total),
        static_cast<unsigned long long>(c.thermal_frozen), c.mean_confidence[0],
        c.mean_confidence[1], c.mean_confidence[2]);
  }
  print_visual_summary(st.estimator);
  const std::string left_off_pose =
      tally.pose_out_of_order > 0
          ? "; " + std::to_string(tally.pose_out_of_order) +
                " state(s) left off pose: stamped before the pose already sent"
          : "";
  if (!r.published)
    std::printf("  published           nothing (offline run, no DDS)\n");
  else
    std::printf("  published           %llu odom, %llu pose, %llu status on DDS domain %d%s%s\n",
                static_cast<unsigned long long>(tally.odom.load()),
                static_cast<unsigned long long>(tally.pose),
                static_cast<unsigned long long>(tally.status), r.config.dds.domain_id,
                tally.failed.load() ? " (some writes failed)" : "", left_off_pose.c_str());
  if (r.published) {
    std::printf("  latency             %s\n",
                r.sinks.odom_latency().line(r.sinks.live_clock()).c_str());
    std::printf("                      %s\n",
                r.sinks.pose_latency().line(r.sinks.live_clock()).c_str());
    if (r.clouds != nullptr) {
      const CloudOutputCounters c = r.clouds->counters();
      std::printf(
          "  point clouds        %llu rt/posed/cloud (last %.2f MB; %llu replaced by a newer "
          "scan before the write), %llu rt/posed/map (last %.2f MB)%s\n",
          static_cast<unsigned long long>(c.clouds), static_cast<double>(c.last_cloud_bytes) / 1e6,
          static_cast<unsigned long long>(c.clouds_replaced),
          static_cast<unsigned long long>(c.maps), static_cast<double>(c.last_map_bytes) / 1e6,
          c.failed ? " (some writes failed)" : "");
    }
    if (r.images != nullptr) {
      const ImageOutputCounters c = r.images->counters();
      std::printf(
          "  images              %llu rt/posed/image/compressed (last %.1f kB JPEG, %.1f ms "
          "to draw and encode on average; %llu replaced by a newer frame)%s\n",
          static_cast<unsigned long long>(c.images), static_cast<double>(c.last_bytes) / 1e3,
          c.images + c.failed > 0 ? c.encode_ms_total / static_cast<double>(c.images + c.failed)
                                  : 0.0,
          static_cast<unsigned long long>(c.replaced), c.failed ? " (some failed)" : "");
    }
    if (r.foxglove != nullptr) {
      const foxglove::ServerStats fs = r.foxglove->stats();
      std::uint64_t sent = 0, dropped = 0;
      std::string per_channel;
      for (const foxglove::ChannelStats& c : fs.channels) {
        sent += c.messages_sent;
        dropped += c.messages_dropped;
        if (c.messages_sent == 0) continue;
        per_channel +=
            (per_channel.empty() ? "" : ", ") + c.topic + " " + std::to_string(c.messages_sent);
      }
      std::printf(
          "  foxglove            port %u: %llu clients; %llu messages sent (%s), %llu "
          "dropped for slow clients, %.1f MB\n",
          r.foxglove->port(), static_cast<unsigned long long>(fs.clients_accepted),
          static_cast<unsigned long long>(sent), per_channel.empty() ? "none" : per_channel.c_str(),
          static_cast<unsigned long long>(dropped), static_cast<double>(fs.bytes_sent) / 1e6);
    }
    const std::string_view mode = r.pipe.odometry_mode();
    std::printf("  odometry            %s\n",
                mode == "imu_thread"
                    ? "propagated on the IMU thread from the newest optimised state"
                : mode == "in_order"
                    ? "propagated from the optimised states in data order (max-speed replay)"
                    : "propagated by the fusion core after each measurement");
  }
  if (r.recorder != nullptr) {
    const auto rc = r.recorder->counters();
    std::printf("  recorded            %llu messages to %s (%.1f MB, %llu dropped)\n",
                static_cast<unsigned long long>(rc.messages_written), r.options.record_path.c_str(),
                static_cast<double>(rc.bytes_on_disk) / 1e6,
                static_cast<unsigned long long>(rc.dropped));
  }
  if (!r.map_line.empty()) std::printf("  map                 %s\n", r.map_line.c_str());
  if (const auto mapping = r.pipe.mapping_figures())
    print_mapping_summary(*mapping, r.sinks.to_wall());
  if (tally.last) {
    const NavState& s = *tally.last;
    std::printf("  final pose          x %.3f m, y %.3f m, z %.3f m, yaw %.1f deg\n",
                s.p_map_base_m.x(), s.p_map_base_m.y(), s.p_map_base_m.z(), yaw_deg(s.q_map_base));
    std::printf("  distance travelled  %.2f m\n", tally.distance_m);
    if (r.synthetic != nullptr) {
      const auto truth = r.synthetic->motion().at(s.stamp - r.synthetic->motion_start());
      std::printf("  vs known motion     position error %.3f m, heading error %.2f deg\n",
                  (s.p_map_base_m - truth.p_map_base_m).norm(),
                  s.q_map_base.angularDistance(truth.q_map_base) * 180.0 / M_PI);
    }
  } else {
    std::printf("  final pose          none (the estimator never aligned: was the IMU static?)\n");
    std::fflush(stdout);
    return false;
  }
  std::fflush(stdout);
  return true;
}

}  // namespace posed
