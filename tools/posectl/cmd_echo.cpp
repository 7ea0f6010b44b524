// posectl echo: subscribes to one of posed's DDS topics and prints each sample with units (or as
// CSV), plus the receive rate [Hz] and stamp-to-receive latency [ms] once a second and at exit.
// Latency is wall clock at receipt minus the message stamp, so it includes the daemon's own
// processing delay (stamp = measurement time), not just DDS transport.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "daemon/dds/subscriber.hpp"
#include "drivers/common/host_clock.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void on_interrupt(int) { g_interrupted.store(true); }

double yaw_deg(const Eigen::Quaterniond& q) {
  const double yaw = std::atan2(2.0 * (q.w() * q.z() + q.x() * q.y()),
                                1.0 - 2.0 * (q.y() * q.y() + q.z() * q.z()));
  return yaw * 180.0 / M_PI;
}

/// "1700000000.123456789" [s] from a wall stamp.
std::string stamp_text(WallTime t) {
  std::int64_t s = t.ns / 1'000'000'000;
  std::int64_t ns = t.ns % 1'000'000'000;
  if (ns < 0) {
    ns += 1'000'000'000;
    s -= 1;
  }
  char buf[40];
  std::snprintf(buf, sizeof buf, "%lld.%09lld", static_cast<long long>(s),
                static_cast<long long>(ns));
  return buf;
}

/// CSV field: quoted when it holds a comma, quote or newline (RFC 4180).
std::string csv(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(p * static_cast<double>(values.size() - 1) + 0.5)];
}

/// A replay stamps its poses with the recording's wall time: receipt minus stamp is then the age
/// of the recording, not a latency, and is not reported as one.
constexpr const char* kNotCurrent =
    "latency n/a (stamps are over an hour off this host's clock: a replayed recording?)";
bool stamps_are_current(double latency_ms) { return std::abs(latency_ms) < 3600e3; }

/// Receive rate and latency, over the window since the last report and over the whole run.
struct EchoStats {
  std::vector<double> latency_ms_all;
  std::size_t window_start = 0;  ///< index into latency_ms_all where the window starts
  HostTime first_receive{};
  HostTime last_receive{};
  HostTime window_begin{};

  void add(WallTime stamp, WallTime received_wall, HostTime received_host) {
    if (latency_ms_all.empty()) first_receive = received_host;
    last_receive = received_host;
    latency_ms_all.push_back((received_wall - stamp).seconds() * 1e3);
  }
  std::size_t count() const { return latency_ms_all.size(); }

  /// One line of rate and latency over the window ending `now`; starts the next window.
  void report_window(std::FILE* out, const char* topic, HostTime now, std::uint32_t publishers) {
    const std::size_t n = latency_ms_all.size() - window_start;
    const double seconds = (now - window_begin).seconds();
    if (n == 0) {
      std::fprintf(out, "# %s: no samples in %.1f s (matched publishers: %u)\n", topic, seconds,
                   publishers);
    } else {
      std::vector<double> window(latency_ms_all.begin() + static_cast<std::ptrdiff_t>(window_start),
                                 latency_ms_all.end());
      const double p50 = percentile(window, 0.50);
      if (stamps_are_current(p50)) {
        std::fprintf(
            out, "# %s: %.1f Hz, latency p50 %.3f ms p99 %.3f ms (%zu samples in %.1f s)\n", topic,
            static_cast<double>(n) / seconds, p50, percentile(window, 0.99), n, seconds);
      } else {
        std::fprintf(out, "# %s: %.1f Hz (%zu samples in %.1f s), %s\n", topic,
                     static_cast<double>(n) / seconds, n, seconds, kNotCurrent);
      }
    }
    std::fflush(out);
    window_start = latency_ms_all.size();
    window_begin = now;
  }

  void report_summary(std::FILE* out, const char* topic) const {
    if (count() == 0) {
      std::fprintf(out, "# summary %s: 0 samples\n", topic);
      std::fflush(out);
      return;
    }
    const double span = (last_receive - first_receive).seconds();
    const double rate = count() >= 2 && span > 0 ? static_cast<double>(count() - 1) / span : 0.0;
    const double p50 = percentile(latency_ms_all, 0.50);
    if (!stamps_are_current(p50)) {
      std::fprintf(out, "# summary %s: %zu samples, rate %.2f Hz, %s\n", topic, count(), rate,
                   kNotCurrent);
      std::fflush(out);
      return;
    }
    std::fprintf(out,
                 "# summary %s: %zu samples, rate %.2f Hz, latency p50 %.3f ms p99 %.3f ms "
                 "max %.3f ms\n",
                 topic, count(), rate, p50, percentile(latency_ms_all, 0.99),
                 *std::max_element(latency_ms_all.begin(), latency_ms_all.end()));
    std::fflush(out);
  }
};

void print_odom_header_csv() {
  std::printf(
      "stamp_s,receive_s,latency_ms,frame_id,child_frame_id,x_m,y_m,z_m,qx,qy,qz,qw,yaw_deg,"
      "vx_mps,vy_mps,vz_mps,wx_radps,wy_radps,wz_radps\n");
}

void print_odom(const dds::Received<dds::OdomMessage>& r, bool as_csv) {
  const auto& m = r.msg;
  const auto& p = m.p_map_base_m;
  const auto& q = m.q_map_base;
  const double lat = (r.received_wall - m.stamp).seconds() * 1e3;
  if (as_csv) {
    std::printf(
        "%s,%s,%.3f,%s,%s,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f,%.3f,%.6f,%.6f,%.6f,%.6f,%.6f,"
        "%.6f\n",
        stamp_text(m.stamp).c_str(), stamp_text(r.received_wall).c_str(), lat,
        csv(r.frame_id).c_str(), csv(r.child_frame_id).c_str(), p.x(), p.y(), p.z(), q.x(), q.y(),
        q.z(), q.w(), yaw_deg(q), m.v_base_mps.x(), m.v_base_mps.y(), m.v_base_mps.z(),
        m.w_base_radps.x(), m.w_base_radps.y(), m.w_base_radps.z());
    return;
  }
  std::printf(
      "odom %s s %s->%s  p [%.3f %.3f %.3f] m  q(xyzw) [%.4f %.4f %.4f %.4f] yaw %.2f deg  "
      "v [%.3f %.3f %.3f] m/s  w [%.3f %.3f %.3f] rad/s  latency %.3f ms\n",
      stamp_text(m.stamp).c_str(), r.frame_id.c_str(), r.child_frame_id.c_str(), p.x(), p.y(),
      p.z(), q.x(), q.y(), q.z(), q.w(), yaw_deg(q), m.v_base_mps.x(), m.v_base_mps.y(),
      m.v_base_mps.z(), m.w_base_radps.x(), m.w_base_radps.y(), m.w_base_radps.z(), lat);
}

void print_pose_header_csv() {
  std::printf("stamp_s,receive_s,latency_ms,frame_id,x_m,y_m,z_m,qx,qy,qz,qw,yaw_deg\n");
}

void print_pose(const dds::Received<dds::PoseMessage>& r, bool as_csv) {
  const auto& m = r.msg;
  const auto& p = m.p_map_base_m;
  const auto& q = m.q_map_base;
  const double lat = (r.received_wall - m.stamp).seconds() * 1e3;
  if (as_csv) {
    std::printf("%s,%s,%.3f,%s,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f,%.3f\n",
                stamp_text(m.stamp).c_str(), stamp_text(r.received_wall).c_str(), lat,
                csv(r.frame_id).c_str(), p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w(),
                yaw_deg(q));
    return;
  }
  std::printf(
      "pose %s s in %s  p [%.3f %.3f %.3f] m  q(xyzw) [%.4f %.4f %.4f %.4f] yaw %.2f deg  "
      "latency %.3f ms\n",
      stamp_text(m.stamp).c_str(), r.frame_id.c_str(), p.x(), p.y(), p.z(), q.x(), q.y(), q.z(),
      q.w(), yaw_deg(q), lat);
}

void print_tf_header_csv() {
  std::printf("stamp_s,receive_s,latency_ms,parent_frame,child_frame,x_m,y_m,z_m,qx,qy,qz,qw\n");
}

/// One line per transform: parent -> child, translation [m], rotation, yaw [deg].
void print_tf(const dds::Received<dds::TfMessage>& r, bool as_csv) {
  for (const auto& t : r.msg.transforms) {
    const auto& p = t.p_parent_child_m;
    const auto& q = t.q_parent_child;
    const double lat = (r.received_wall - t.stamp).seconds() * 1e3;
    if (as_csv) {
      std::printf("%s,%s,%.3f,%s,%s,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.9f\n",
                  stamp_text(t.stamp).c_str(), stamp_text(r.received_wall).c_str(), lat,
                  csv(t.parent_frame).c_str(), csv(t.child_frame).c_str(), p.x(), p.y(), p.z(),
                  q.x(), q.y(), q.z(), q.w());
    } else {
      std::printf(
          "tf %s s  %s -> %s  p [%.3f %.3f %.3f] m  q(xyzw) [%.4f %.4f %.4f %.4f] yaw %.2f deg\n",
          stamp_text(t.stamp).c_str(), t.parent_frame.c_str(), t.child_frame.c_str(), p.x(), p.y(),
          p.z(), q.x(), q.y(), q.z(), q.w(), yaw_deg(q));
    }
  }
}

void print_path_header_csv() {
  std::printf("stamp_s,receive_s,latency_ms,frame_id,poses,x_m,y_m,z_m\n");
}

/// One line per message: how many poses, and the newest.
void print_path(const dds::Received<dds::PathMessage>& r, bool as_csv) {
  const auto& m = r.msg;
  const double lat = (r.received_wall - m.stamp).seconds() * 1e3;
  const Eigen::Vector3d p = m.poses.empty() ? Eigen::Vector3d::Zero() : m.poses.back().p_map_base_m;
  if (as_csv) {
    std::printf("%s,%s,%.3f,%s,%zu,%.6f,%.6f,%.6f\n", stamp_text(m.stamp).c_str(),
                stamp_text(r.received_wall).c_str(), lat, csv(r.frame_id).c_str(), m.poses.size(),
                p.x(), p.y(), p.z());
    return;
  }
  std::printf("path %s s in %s  %zu poses, newest p [%.3f %.3f %.3f] m\n",
              stamp_text(m.stamp).c_str(), r.frame_id.c_str(), m.poses.size(), p.x(), p.y(), p.z());
}

void print_cloud_header_csv() {
  std::printf("stamp_s,receive_s,latency_ms,frame_id,points,point_step_B,data_B,fields\n");
}

/// "x:float32@0 y:float32@4 ..." as PointField describes the layout.
std::string cloud_fields(const dds::CloudMessage& m) {
  static const char* kTypes[] = {"?",     "int8",   "uint8",   "int16",  "uint16",
                                 "int32", "uint32", "float32", "float64"};
  std::string s;
  for (const auto& f : m.fields) {
    if (!s.empty()) s += ' ';
    s += f.name + ':' + (f.datatype <= 8 ? kTypes[f.datatype] : "?") + '@' +
         std::to_string(f.offset);
  }
  return s;
}

/// One line per cloud: size, layout and the extent of its x y z (float32 at 0, 4, 8).
void print_cloud(const dds::Received<dds::CloudMessage>& r, bool as_csv) {
  const auto& m = r.msg;
  const double lat = (r.received_wall - m.stamp).seconds() * 1e3;
  if (as_csv) {
    std::printf("%s,%s,%.3f,%s,%u,%u,%zu,%s\n", stamp_text(m.stamp).c_str(),
                stamp_text(r.received_wall).c_str(), lat, csv(r.frame_id).c_str(), m.width,
                m.point_step, m.data.size(), csv(cloud_fields(m)).c_str());
    return;
  }
  Eigen::Array3f lo = Eigen::Array3f::Constant(0), hi = Eigen::Array3f::Constant(0);
  const bool xyz = m.point_step >= 12 && m.data.size() >= std::size_t{m.width} * m.point_step;
  for (std::uint32_t i = 0; xyz && i < m.width; ++i) {
    Eigen::Array3f p;
    std::memcpy(p.data(), m.data.data() + std::size_t{i} * m.point_step, 12);
    lo = i == 0 ? p : lo.min(p);
    hi = i == 0 ? p : hi.max(p);
  }
  std::printf(
      "cloud %s s in %s  %u points x %u B (%.2f MB)  x [%.1f %.1f] y [%.1f %.1f] z [%.1f %.1f] m"
      "  fields %s\n",
      stamp_text(m.stamp).c_str(), r.frame_id.c_str(), m.width, m.point_step,
      static_cast<double>(m.data.size()) / 1e6, lo.x(), hi.x(), lo.y(), hi.y(), lo.z(), hi.z(),
      cloud_fields(m).c_str());
}

void print_image_header_csv() {
  std::printf("stamp_s,receive_s,latency_ms,frame_id,format,bytes,width_px,height_px\n");
}

/// One line per image: format, size, and its dimensions once decoded (0 x 0: it does not decode).
void print_image(const dds::Received<dds::ImageMessage>& r, bool as_csv) {
  const auto& m = r.msg;
  const double lat = (r.received_wall - m.stamp).seconds() * 1e3;
  const cv::Mat decoded = cv::imdecode(cv::Mat(1, static_cast<int>(m.data.size()), CV_8UC1,
                                               const_cast<std::uint8_t*>(m.data.data())),
                                       cv::IMREAD_UNCHANGED);
  if (as_csv) {
    std::printf("%s,%s,%.3f,%s,%s,%zu,%d,%d\n", stamp_text(m.stamp).c_str(),
                stamp_text(r.received_wall).c_str(), lat, csv(r.frame_id).c_str(),
                csv(m.format).c_str(), m.data.size(), decoded.cols, decoded.rows);
    return;
  }
  std::printf("image %s s in %s  %s %.1f kB, %d x %d px\n", stamp_text(m.stamp).c_str(),
              r.frame_id.c_str(), m.format.c_str(), static_cast<double>(m.data.size()) / 1e3,
              decoded.cols, decoded.rows);
}

void print_diagnostics_header_csv() {
  std::printf("stamp_s,receive_s,latency_ms,level,name,message,hardware_id,values\n");
}

/// One line per status: level, name, message, then key=value pairs.
void print_diagnostics(const dds::Received<dds::DiagnosticsMessage>& r, bool as_csv) {
  static const char* kLevels[] = {"OK", "WARN", "ERROR", "STALE"};
  const auto& m = r.msg;
  const double lat = (r.received_wall - m.stamp).seconds() * 1e3;
  for (const auto& d : m.status) {
    const char* level = d.level < 4 ? kLevels[d.level] : "?";
    std::string values;
    for (const auto& [key, value] : d.values) {
      values += (values.empty() ? "" : as_csv ? ";" : "  ") + key + "=" + value;
    }
    if (as_csv) {
      std::printf("%s,%s,%.3f,%s,%s,%s,%s,%s\n", stamp_text(m.stamp).c_str(),
                  stamp_text(r.received_wall).c_str(), lat, level, csv(d.name).c_str(),
                  csv(d.message).c_str(), csv(d.hardware_id).c_str(), csv(values).c_str());
    } else {
      std::printf("diagnostics %s s  %-5s %s: %s  [%s]\n", stamp_text(m.stamp).c_str(), level,
                  d.name.c_str(), d.message.c_str(), values.c_str());
    }
  }
}

void print_status_header_csv() {
  std::printf(
      "stamp_s,receive_s,latency_ms,version,estimator_mode,uptime_s,summary,stream,rate_hz,"
      "received,decoded,dropped,malformed,clock_offset_ns,clock_drift_ppm,clock_jitter_ns,"
      "clock_uncertainty_ns,clock_state,health,mapping_state,mapping_keyframes,mapping_loops,"
      "mapping_fixes,mapping_correction_m\n");
}

void print_status(const dds::Received<dds::StatusMessage>& r, bool as_csv) {
  const auto& m = r.msg;
  const double lat = (r.received_wall - m.stamp).seconds() * 1e3;
  if (as_csv) {
    // One row per stream (a status without streams still gets one row).
    const std::string prefix = stamp_text(m.stamp) + "," + stamp_text(r.received_wall) + "," +
                               std::to_string(lat) + "," + csv(m.version) + "," +
                               csv(m.estimator_mode) + "," + std::to_string(m.uptime_s) + "," +
                               csv(m.summary);
    // The mapping stage's figures end every row.
    char mapping[160];
    std::snprintf(mapping, sizeof mapping, "%s,%llu,%llu,%llu,%.3f", csv(m.mapping.state).c_str(),
                  static_cast<unsigned long long>(m.mapping.keyframes),
                  static_cast<unsigned long long>(m.mapping.loops),
                  static_cast<unsigned long long>(m.mapping.fixes), m.mapping.correction_m);
    if (m.streams.empty()) std::printf("%s,,,,,,,,,,,,,%s\n", prefix.c_str(), mapping);
    for (const auto& s : m.streams) {
      std::printf(
          "%s,%s,%.3f,%llu,%llu,%llu,%llu,%lld,%.3f,%.1f,%.1f,%s,%s,%s\n", prefix.c_str(),
          csv(s.name).c_str(), s.rate_hz, static_cast<unsigned long long>(s.received),
          static_cast<unsigned long long>(s.decoded), static_cast<unsigned long long>(s.dropped),
          static_cast<unsigned long long>(s.malformed), static_cast<long long>(s.clock_offset_ns),
          s.clock_drift_ppm, s.clock_jitter_ns, s.clock_uncertainty_ns, csv(s.clock_state).c_str(),
          csv(s.health).c_str(), mapping);
    }
    return;
  }
  std::printf("status %s s  %s  mode %s  uptime %.1f s  latency %.3f ms  %s\n",
              stamp_text(m.stamp).c_str(), m.version.c_str(), m.estimator_mode.c_str(), m.uptime_s,
              lat, m.summary.c_str());
  const dds::EstimatorStatusMessage& e = m.estimator;
  std::printf(
      "  estimator  scans used %llu rejected %llu degenerate %llu skipped %llu  keyframes %llu  "
      "re-initialisations %llu  last match %d degenerate directions  bias gyro [%.5f %.5f %.5f] "
      "rad/s accel [%.4f %.4f %.4f] m/s^2\n",
      static_cast<unsigned long long>(e.scans_used),
      static_cast<unsigned long long>(e.scans_rejected),
      static_cast<unsigned long long>(e.scans_degenerate),
      static_cast<unsigned long long>(e.scans_skipped),
      static_cast<unsigned long long>(e.keyframes),
      static_cast<unsigned long long>(e.reinitialisations), e.degenerate_directions,
      e.gyro_bias_radps.x(), e.gyro_bias_radps.y(), e.gyro_bias_radps.z(), e.accel_bias_mps2.x(),
      e.accel_bias_mps2.y(), e.accel_bias_mps2.z());
  if (!m.camera.mode.empty()) {
    const dds::CameraStatusMessage& c = m.camera;
    std::printf(
        "  cameras    %s front end: %llu frames (%llu unusable)  last frame %d features, %d with "
        "lidar depth  match success %.1f %%  confidence visible %.2f thermal %.2f fused %.2f  "
        "omega %.1f %.1f %.1f\n",
        c.mode.c_str(), static_cast<unsigned long long>(c.frames),
        static_cast<unsigned long long>(c.frames_unusable), c.features, c.depth_associated,
        100.0 * c.match_success_rate, c.confidence[0], c.confidence[1], c.confidence[2], c.omega[0],
        c.omega[1], c.omega[2]);
  }
  static constexpr const char* kVisual[] = {"visible", "thermal", "fused"};
  bool any_visual = false;
  for (std::size_t i = 0; i < 3; ++i) {
    const dds::VisualStreamStatusMessage& v = m.visual[i];
    if (!v.configured) continue;
    if (!any_visual) std::printf("  estimate   %s at the last state\n", m.modalities.c_str());
    any_visual = true;
    std::printf(
        "  %-10s %s  omega %.2f confidence %.2f  factors %llu failed %llu gated out %llu (left "
        "%llu, rejoined %llu), %llu from a keyframe  last %d inliers (%d still left out) %.2f px  "
        "window residual median %.2f sigma\n",
        kVisual[i], v.active ? "in the estimate" : "gated out", v.omega, v.confidence,
        static_cast<unsigned long long>(v.factors), static_cast<unsigned long long>(v.failed),
        static_cast<unsigned long long>(v.gated_out), static_cast<unsigned long long>(v.left),
        static_cast<unsigned long long>(v.rejoined),
        static_cast<unsigned long long>(v.keyframe_factors), v.inliers, v.still,
        v.reprojection_rms_px, v.residual_median);
  }
  const dds::PoseSelectionStatusMessage& sel = m.selection;
  if (sel.lidar_visual_inertial + sel.lidar_inertial + sel.visual_inertial + sel.imu_only > 0) {
    std::printf(
        "  selection  initial values: %llu lidar-visual-inertial %llu lidar-inertial %llu "
        "visual-inertial %llu IMU only  threshold %.3f m\n",
        static_cast<unsigned long long>(sel.lidar_visual_inertial),
        static_cast<unsigned long long>(sel.lidar_inertial),
        static_cast<unsigned long long>(sel.visual_inertial),
        static_cast<unsigned long long>(sel.imu_only), sel.threshold_m);
  }
  const dds::MappingStatusMessage& map = m.mapping;
  if (map.state == "off") {
    std::printf("  mapping    off\n");
  } else {
    std::printf(
        "  mapping    state %s  keyframes %llu loops %llu fixes %llu  map -> odom %.3f m  scans "
        "skipped %llu\n",
        map.state.c_str(), static_cast<unsigned long long>(map.keyframes),
        static_cast<unsigned long long>(map.loops), static_cast<unsigned long long>(map.fixes),
        map.correction_m, static_cast<unsigned long long>(map.scans_skipped));
  }
  for (const auto& s : m.streams) {
    std::printf(
        "  %-10s %8.2f Hz  received %llu decoded %llu dropped %llu malformed %llu  clock %s: "
        "offset %lld ns drift %.3f ppm jitter %.0f ns uncertainty %.0f ns  health %s\n",
        s.name.c_str(), s.rate_hz, static_cast<unsigned long long>(s.received),
        static_cast<unsigned long long>(s.decoded), static_cast<unsigned long long>(s.dropped),
        static_cast<unsigned long long>(s.malformed), s.clock_state.c_str(),
        static_cast<long long>(s.clock_offset_ns), s.clock_drift_ppm, s.clock_jitter_ns,
        s.clock_uncertainty_ns, s.health.c_str());
  }
  for (const auto& l : m.latency) {
    if (l.topic.empty() || l.count == 0) continue;
    if (!l.live) {
      std::printf(
          "  latency    %-14s %llu written  n/a (a replay's stamps, not this host's clock "
          "now: replay with --live-stamps)\n",
          l.topic.c_str(), static_cast<unsigned long long>(l.count));
      continue;
    }
    std::printf(
        "  latency    %-14s %llu written  receive->write p50 %.3f p99 %.3f max %.3f ms  stamp "
        "age p50 %.3f p99 %.3f max %.3f ms\n",
        l.topic.c_str(), static_cast<unsigned long long>(l.count), l.receive_to_write_p50_ms,
        l.receive_to_write_p99_ms, l.receive_to_write_max_ms, l.stamp_age_p50_ms,
        l.stamp_age_p99_ms, l.stamp_age_max_ms);
  }
}

/// `--tum FILE`: poses as a TUM trajectory (`stamp x y z qx qy qz qw`, stamp [s] wall time, as
/// posed stamps them), for `posectl eval` against ground truth.
void write_tum(std::FILE* tum, WallTime stamp, const Eigen::Vector3d& p,
               const Eigen::Quaterniond& q) {
  std::fprintf(tum, "%s %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n", stamp_text(stamp).c_str(), p.x(),
               p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
}
void write_tum(std::FILE* tum, const dds::Received<dds::OdomMessage>& r) {
  write_tum(tum, r.msg.stamp, r.msg.p_map_base_m, r.msg.q_map_base);
}
void write_tum(std::FILE* tum, const dds::Received<dds::PoseMessage>& r) {
  write_tum(tum, r.msg.stamp, r.msg.p_map_base_m, r.msg.q_map_base);
}
void write_tum(std::FILE*, const dds::Received<dds::StatusMessage>&) {}
void write_tum(std::FILE*, const dds::Received<dds::TfMessage>&) {}
void write_tum(std::FILE*, const dds::Received<dds::PathMessage>&) {}
void write_tum(std::FILE*, const dds::Received<dds::DiagnosticsMessage>&) {}
void write_tum(std::FILE*, const dds::Received<dds::CloudMessage>&) {}
void write_tum(std::FILE*, const dds::Received<dds::ImageMessage>&) {}

/// The stamp a message's latency is measured from (a tf message: its first transform's).
WallTime stamp_of(const dds::OdomMessage& m) { return m.stamp; }
WallTime stamp_of(const dds::PoseMessage& m) { return m.stamp; }
WallTime stamp_of(const dds::StatusMessage& m) { return m.stamp; }
WallTime stamp_of(const dds::PathMessage& m) { return m.stamp; }
WallTime stamp_of(const dds::DiagnosticsMessage& m) { return m.stamp; }
WallTime stamp_of(const dds::CloudMessage& m) { return m.stamp; }
WallTime stamp_of(const dds::ImageMessage& m) { return m.stamp; }
WallTime stamp_of(const dds::TfMessage& m) {
  return m.transforms.empty() ? WallTime{} : m.transforms.front().stamp;
}

/// Takes everything waiting on `topic`, prints it, feeds the stats; returns how many.
template <class Message, class Take, class Print>
std::size_t drain(Take take, Print print, bool as_csv, std::FILE* tum, EchoStats& stats,
                  std::size_t limit) {
  std::vector<dds::Received<Message>> samples;
  take(samples);
  std::size_t printed = 0;
  for (const auto& r : samples) {
    if (limit != 0 && stats.count() >= limit) break;  // exactly --count lines
    if (tum != nullptr) {
      write_tum(tum, r);
    } else {
      print(r, as_csv);
    }
    stats.add(stamp_of(r.msg), r.received_wall, r.received_host);
    ++printed;
  }
  std::fflush(stdout);
  return printed;
}

}  // namespace

int run_echo(int argc, char** argv) {
  CLI::App app{
      "Print samples of one of posed's DDS topics (ROS 2 types) with units, or as CSV.\n"
      "Reports receive rate [Hz] and stamp-to-receive latency [ms] every second and at exit.",
      "posectl echo"};
  std::string topic_arg = "rt/posed/odom";
  bool as_csv = false;
  std::size_t count = 0;
  double timeout_s = 0.0;
  std::uint32_t domain = 0;
  std::string cyclone_config;
  std::string tum_path;
  std::string enclave;
  app.add_option(
         "topic", topic_arg,
         "odom, pose, status, tf, tf_static, path, diagnostics, cloud, map, image, or the full DDS "
         "name (rt/posed/odom, rt/tf) or ROS name")
      ->capture_default_str();
  app.add_flag("--csv", as_csv,
               "CSV with a header line on stdout; rate/latency reports go to stderr");
  app.add_option("--count,-n", count, "exit 0 after N samples (0: until Ctrl-C or --timeout)");
  app.add_option("--timeout,-t", timeout_s,
                 "give up after S seconds [s]; fails unless --count was reached (or, without "
                 "--count, unless anything arrived). 0: no limit")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--domain,-d", domain, "DDS domain id (ROS_DOMAIN_ID)")->capture_default_str();
  app.add_option("--cyclonedds-config", cyclone_config,
                 "Cyclone XML file (e.g. config/cyclonedds-loopback.xml); default: CYCLONEDDS_URI "
                 "or Cyclone's built-in defaults");
  app.add_option("--tum", tum_path,
                 "write odom/pose samples to this file as a TUM trajectory (stamp [s] x y z qx qy "
                 "qz qw) instead of printing them; for `posectl eval`");
  app.add_option("--enclave", enclave,
                 "DDS Security: an SROS2 enclave directory allowed to read posed's topics "
                 "(posectl security init DIR makes DIR/enclaves/posectl)")
      ->check(CLI::ExistingDirectory);
  CLI11_PARSE(app, argc, argv);

  dds::Topic topic = dds::Topic::kOdom;
  if (!dds::parse_topic(topic_arg, topic)) {
    std::fprintf(stderr,
                 "posectl echo: unknown topic '%s' (expected odom, pose, status, path, tf, "
                 "tf_static, diagnostics, cloud, map, image, or their DDS names "
                 "rt/posed/{odom,pose,status,path,cloud,map}, rt/posed/image/compressed, rt/tf, "
                 "rt/tf_static, rt/diagnostics)\n",
                 topic_arg.c_str());
    return 2;
  }
  const std::string topic_name(dds::topic_name(topic));
  if (!tum_path.empty() && topic != dds::Topic::kOdom && topic != dds::Topic::kPose) {
    std::fprintf(stderr, "posectl echo: --tum needs a pose topic (odom or pose), not %s\n",
                 topic_arg.c_str());
    return 2;
  }
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> tum(nullptr, &std::fclose);
  if (!tum_path.empty()) {
    tum.reset(std::fopen(tum_path.c_str(), "w"));
    if (!tum) {
      std::fprintf(stderr, "posectl echo: cannot write %s: %s\n", tum_path.c_str(),
                   std::strerror(errno));
      return 1;
    }
  }

  dds::DdsConfig config;
  config.domain_id = domain;
  config.cyclonedds_xml_path = cyclone_config;
  if (!enclave.empty()) config.security = dds::DdsSecurityFiles::from_enclave(enclave);
  std::string error;
  const std::array topics = {topic};
  auto subscriber = dds::Subscriber::create(config, topics, error);
  if (!subscriber) {
    std::fprintf(stderr, "posectl echo: %s\n", error.c_str());
    return 1;
  }

  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
  std::FILE* report_out = as_csv ? stderr : stdout;
  if (as_csv && !tum) {
    if (topic == dds::Topic::kOdom) print_odom_header_csv();
    if (topic == dds::Topic::kPose) print_pose_header_csv();
    if (topic == dds::Topic::kStatus) print_status_header_csv();
    if (topic == dds::Topic::kTf || topic == dds::Topic::kTfStatic) print_tf_header_csv();
    if (topic == dds::Topic::kPath) print_path_header_csv();
    if (topic == dds::Topic::kDiagnostics) print_diagnostics_header_csv();
    if (topic == dds::Topic::kCloud || topic == dds::Topic::kMap) print_cloud_header_csv();
    if (topic == dds::Topic::kImage) print_image_header_csv();
  }
  std::fprintf(stderr, "posectl echo: listening on %s (domain %u)\n", topic_name.c_str(), domain);

  EchoStats stats;
  const HostTime start = drivers::host_now();
  stats.window_begin = start;
  const Duration report_every = Duration::from_s(1);
  const Duration limit = Duration::from_seconds(timeout_s);
  bool timed_out = false;
  while (!g_interrupted.load() && (count == 0 || stats.count() < count)) {
    const HostTime now = drivers::host_now();
    if (timeout_s > 0 && now - start >= limit) {
      timed_out = true;
      break;
    }
    if (now - stats.window_begin >= report_every) {
      stats.report_window(report_out, topic_name.c_str(), now,
                          subscriber->matched_publishers(topic));
    }
    // Short waits keep Ctrl-C, the timeout and the periodic report responsive.
    if (!subscriber->wait(Duration::from_ms(100))) continue;
    switch (topic) {
      case dds::Topic::kOdom:
        drain<dds::OdomMessage>([&](auto& v) { subscriber->take_odom(v); }, print_odom, as_csv,
                                tum.get(), stats, count);
        break;
      case dds::Topic::kPose:
        drain<dds::PoseMessage>([&](auto& v) { subscriber->take_pose(v); }, print_pose, as_csv,
                                tum.get(), stats, count);
        break;
      case dds::Topic::kStatus:
        drain<dds::StatusMessage>([&](auto& v) { subscriber->take_status(v); }, print_status,
                                  as_csv, nullptr, stats, count);
        break;
      case dds::Topic::kTf:
      case dds::Topic::kTfStatic:
        drain<dds::TfMessage>([&](auto& v) { subscriber->take_tf(topic, v); }, print_tf, as_csv,
                              nullptr, stats, count);
        break;
      case dds::Topic::kPath:
        drain<dds::PathMessage>([&](auto& v) { subscriber->take_path(v); }, print_path, as_csv,
                                nullptr, stats, count);
        break;
      case dds::Topic::kDiagnostics:
        drain<dds::DiagnosticsMessage>([&](auto& v) { subscriber->take_diagnostics(v); },
                                       print_diagnostics, as_csv, nullptr, stats, count);
        break;
      case dds::Topic::kCloud:
      case dds::Topic::kMap:
        drain<dds::CloudMessage>([&](auto& v) { subscriber->take_cloud(topic, v); }, print_cloud,
                                 as_csv, nullptr, stats, count);
        break;
      case dds::Topic::kImage:
        drain<dds::ImageMessage>([&](auto& v) { subscriber->take_image(v); }, print_image, as_csv,
                                 nullptr, stats, count);
        break;
    }
  }
  stats.report_summary(report_out, topic_name.c_str());

  const bool short_of_count = count != 0 && stats.count() < count;
  if (short_of_count || (timed_out && stats.count() == 0)) {
    std::fprintf(stderr,
                 "posectl echo: %s: %zu of %s samples on %s (domain %u) after %.1f s; matched "
                 "publishers: %u (is posed running with the same domain and Cyclone config?)\n",
                 timed_out ? "timeout" : "interrupted", stats.count(),
                 count != 0 ? std::to_string(count).c_str() : "at least 1", topic_name.c_str(),
                 domain, (drivers::host_now() - start).seconds(),
                 subscriber->matched_publishers(topic));
    return 1;
  }
  return 0;
}

}  // namespace posed::posectl
