#include "daemon/ros_outputs.hpp"

#include <Eigen/Geometry>
#include <cstdio>
#include <string>

namespace posed {
namespace {

Eigen::Matrix4d matrix(const config::Transform4& T) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = T[static_cast<std::size_t>(r * 4 + c)];
  }
  return m;
}

/// T_parent_child as the transform tf2 sends for child in parent.
dds::TransformMessage transform(const Eigen::Matrix4d& T, WallTime stamp, const std::string& parent,
                                const std::string& child) {
  dds::TransformMessage t;
  t.stamp = stamp;
  t.parent_frame = parent;
  t.child_frame = child;
  t.p_parent_child_m = T.block<3, 1>(0, 3);
  t.q_parent_child = Eigen::Quaterniond(Eigen::Matrix3d(T.block<3, 3>(0, 0))).normalized();
  return t;
}

std::string number(double value, const char* unit) {
  char text[64];
  std::snprintf(text, sizeof text, "%.3f %s", value, unit);
  return text;
}

std::uint8_t stream_level(const std::string& health) {
  using L = dds::DiagnosticStatusMessage;
  if (health == "ok") return L::kOk;
  if (health == "degraded") return L::kWarn;
  if (health == "no_data") return L::kStale;
  return L::kError;  // device_lost, or a verdict this code does not know
}

}  // namespace

dds::TfMessage static_transforms(const config::PosedConfig& config, WallTime stamp) {
  const auto& e = config.extrinsics;
  const auto& d = config.dds;
  dds::TfMessage msg;
  msg.transforms = {transform(matrix(e.T_imu_lidar), stamp, d.base_frame, d.lidar_frame),
                    transform(matrix(e.T_imu_cam), stamp, d.base_frame, d.camera_frame),
                    transform(matrix(e.T_imu_cam) * matrix(e.T_cam_thermal), stamp, d.base_frame,
                              d.thermal_frame)};
  return msg;
}

dds::TfMessage tf_tree(const config::DdsSection& dds, const NavState& s,
                       const Eigen::Isometry3d& T_map_odom, WallTime stamp) {
  dds::TfMessage msg;
  msg.transforms.resize(2);
  msg.transforms[0].stamp = stamp;
  msg.transforms[0].parent_frame = dds.map_frame;
  msg.transforms[0].child_frame = dds.odom_frame;
  msg.transforms[0].p_parent_child_m = T_map_odom.translation();
  msg.transforms[0].q_parent_child = Eigen::Quaterniond(T_map_odom.rotation()).normalized();
  msg.transforms[1].stamp = stamp;
  msg.transforms[1].parent_frame = dds.odom_frame;
  msg.transforms[1].child_frame = dds.base_frame;
  msg.transforms[1].p_parent_child_m = s.p_map_base_m;
  msg.transforms[1].q_parent_child = s.q_map_base;
  return msg;
}

dds::DiagnosticsMessage diagnostics(const pipeline::PipelineStatus& st, WallTime stamp) {
  dds::DiagnosticsMessage msg;
  msg.stamp = stamp;
  for (const auto& s : st.streams) {
    dds::DiagnosticStatusMessage d;
    d.level = stream_level(s.health);
    d.name = "posed: " + s.name;
    d.message = s.health + ", clock " + s.clock_state;
    d.hardware_id = s.name;
    d.values = {{"rate", number(s.rate_hz, "Hz")},
                {"received", std::to_string(s.received)},
                {"decoded", std::to_string(s.decoded)},
                {"malformed", std::to_string(s.malformed)},
                {"refused", std::to_string(s.refused)},
                {"dropped", std::to_string(s.dropped)},
                {"clock state", s.clock_state},
                {"clock offset", number(static_cast<double>(s.clock_offset_ns) * 1e-6, "ms")},
                {"clock drift", number(s.clock_drift_ppm, "ppm")}};
    msg.status.push_back(std::move(d));
  }
  const FusionFigures& f = st.estimator;
  dds::DiagnosticStatusMessage e;
  e.name = "posed: estimator";
  e.hardware_id = "fusion core";
  const std::string mode(to_string(st.mode));
  // Aligning: no pose yet. Dropped states: the publisher could not keep up.
  e.level = st.mode == EstimatorMode::kAligning || st.states_dropped > 0
                ? dds::DiagnosticStatusMessage::kWarn
                : dds::DiagnosticStatusMessage::kOk;
  e.message = mode;
  e.values = {{"mode", mode},
              {"states", std::to_string(st.states)},
              {"states dropped", std::to_string(st.states_dropped)},
              {"scans used", std::to_string(f.scans_used)},
              {"scans rejected", std::to_string(f.scans_rejected)},
              {"scans degenerate", std::to_string(f.scans_degenerate)},
              {"reinitialisations", std::to_string(f.reinitialisations)}};
  msg.status.push_back(std::move(e));
  if (st.mapping) {
    const pipeline::MappingStatus& m = *st.mapping;
    dds::DiagnosticStatusMessage d;
    d.name = "posed: mapping";
    d.hardware_id = "mapping stage";
    // Localising and not localised: poses are not in the prior map's frame yet (or any more).
    d.level = m.localising && m.state != "localised" ? dds::DiagnosticStatusMessage::kWarn
                                                     : dds::DiagnosticStatusMessage::kOk;
    d.message = m.state;
    d.values = {{"state", m.state},
                {"map -> odom", number(m.correction_m, "m")},
                {"scans skipped", std::to_string(m.scans_skipped)}};
    if (m.localising) {
      d.values.push_back({"fixes", std::to_string(m.fixes)});
    } else {
      d.values.push_back({"keyframes", std::to_string(m.keyframes)});
      d.values.push_back({"loops", std::to_string(m.loops)});
    }
    msg.status.push_back(std::move(d));
  }
  return msg;
}

void PathBuilder::add(const dds::PoseMessage& pose) {
  path_.stamp = pose.stamp;
  auto& poses = path_.poses;
  // The path always ends at the newest pose: it replaces the last one while the base is still
  // within a step of the one before.
  if (poses.size() >= 2 &&
      (pose.p_map_base_m - poses[poses.size() - 2].p_map_base_m).norm() < min_step_m_) {
    poses.back() = pose;
    return;
  }
  poses.push_back(pose);
  if (poses.size() <= max_poses_) return;
  // Keep the first, every other one after it, and the newest.
  std::vector<dds::PoseMessage> thinned;
  thinned.reserve(poses.size() / 2 + 2);
  for (std::size_t i = 0; i + 1 < poses.size(); i += 2) thinned.push_back(poses[i]);
  thinned.push_back(poses.back());
  poses.swap(thinned);
}

}  // namespace posed
