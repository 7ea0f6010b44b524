#include "daemon/dds/convert.hpp"

#include <algorithm>

namespace posed::dds::detail {
namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

/// Cyclone reads the sample during dds_write only; it never writes through these pointers.
char* c_str(const std::string& s) { return const_cast<char*>(s.c_str()); }

geometry_msgs_msg_dds__Point_ to_point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }
geometry_msgs_msg_dds__Vector3_ to_vector(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}
geometry_msgs_msg_dds__Quaternion_ to_quaternion(const Eigen::Quaterniond& q) {
  return {q.x(), q.y(), q.z(), q.w()};
}
Eigen::Vector3d from_point(const geometry_msgs_msg_dds__Point_& p) { return {p.x, p.y, p.z}; }
Eigen::Vector3d from_vector(const geometry_msgs_msg_dds__Vector3_& v) { return {v.x, v.y, v.z}; }
Eigen::Quaterniond from_quaternion(const geometry_msgs_msg_dds__Quaternion_& q) {
  return Eigen::Quaterniond(q.w, q.x, q.y, q.z);  // Eigen's constructor takes w first
}

}  // namespace

builtin_interfaces_msg_dds__Time_ to_ros_time(WallTime stamp) {
  std::int64_t sec = stamp.ns / kNsPerS;
  std::int64_t nanosec = stamp.ns % kNsPerS;
  if (nanosec < 0) {  // ROS keeps nanosec positive: -0.5 s is sec -1, nanosec 5e8
    nanosec += kNsPerS;
    sec -= 1;
  }
  return {static_cast<std::int32_t>(sec), static_cast<std::uint32_t>(nanosec)};
}

WallTime from_ros_time(const builtin_interfaces_msg_dds__Time_& time) {
  return WallTime::from_ns(static_cast<std::int64_t>(time.sec) * kNsPerS +
                           static_cast<std::int64_t>(time.nanosec));
}

void fill_odom(const OdomMessage& msg, nav_msgs_msg_dds__Odometry_& out) {
  out.header.stamp = to_ros_time(msg.stamp);
  out.pose.pose.position = to_point(msg.p_map_base_m);
  out.pose.pose.orientation = to_quaternion(msg.q_map_base);
  std::copy(msg.pose_covariance.begin(), msg.pose_covariance.end(), out.pose.covariance);
  out.twist.twist.linear = to_vector(msg.v_base_mps);
  out.twist.twist.angular = to_vector(msg.w_base_radps);
  std::copy(msg.twist_covariance.begin(), msg.twist_covariance.end(), out.twist.covariance);
}

void fill_pose(const PoseMessage& msg, geometry_msgs_msg_dds__PoseStamped_& out) {
  out.header.stamp = to_ros_time(msg.stamp);
  out.pose.position = to_point(msg.p_map_base_m);
  out.pose.orientation = to_quaternion(msg.q_map_base);
}

void fill_status(const StatusMessage& msg, posed_msgs_msg_dds__Status_& out,
                 std::vector<posed_msgs_msg_dds__StreamStatus_>& streams) {
  out.header.stamp = to_ros_time(msg.stamp);
  out.version = c_str(msg.version);
  out.estimator_mode = c_str(msg.estimator_mode);
  const EstimatorStatusMessage& e = msg.estimator;
  out.estimator.scans_used = e.scans_used;
  out.estimator.scans_rejected = e.scans_rejected;
  out.estimator.scans_degenerate = e.scans_degenerate;
  out.estimator.scans_skipped = e.scans_skipped;
  out.estimator.reinitialisations = e.reinitialisations;
  out.estimator.keyframes = e.keyframes;
  out.estimator.degenerate_directions = e.degenerate_directions;
  for (int i = 0; i < 3; ++i) {
    out.estimator.gyro_bias_radps[i] = e.gyro_bias_radps[i];
    out.estimator.accel_bias_mps2[i] = e.accel_bias_mps2[i];
  }
  const CameraStatusMessage& cam = msg.camera;
  out.camera.mode = c_str(cam.mode);
  out.camera.frames = cam.frames;
  out.camera.frames_unusable = cam.frames_unusable;
  out.camera.features = cam.features;
  out.camera.depth_associated = cam.depth_associated;
  out.camera.match_success_rate = cam.match_success_rate;
  for (std::size_t i = 0; i < 3; ++i) {
    out.camera.confidence[i] = cam.confidence[i];
    out.camera.omega[i] = cam.omega[i];
  }
  out.modalities = c_str(msg.modalities);
  for (std::size_t i = 0; i < 3; ++i) {
    const VisualStreamStatusMessage& v = msg.visual[i];
    posed_msgs_msg_dds__VisualStreamStatus_& d = out.visual[i];
    d.configured = v.configured;
    d.active = v.active;
    d.omega = v.omega;
    d.confidence = v.confidence;
    d.factors = v.factors;
    d.failed = v.failed;
    d.gated_out = v.gated_out;
    d.left = v.left;
    d.rejoined = v.rejoined;
    d.inliers = v.inliers;
    d.reprojection_rms_px = v.reprojection_rms_px;
    d.residual_median = v.residual_median;
    d.keyframe_factors = v.keyframe_factors;
    d.still = v.still;
  }
  out.selection.lidar_visual_inertial = msg.selection.lidar_visual_inertial;
  out.selection.lidar_inertial = msg.selection.lidar_inertial;
  out.selection.visual_inertial = msg.selection.visual_inertial;
  out.selection.imu_only = msg.selection.imu_only;
  out.selection.threshold_m = msg.selection.threshold_m;
  out.uptime_s = msg.uptime_s;
  out.summary = c_str(msg.summary);
  if (streams.size() < msg.streams.size()) streams.resize(msg.streams.size());
  for (std::size_t i = 0; i < msg.streams.size(); ++i) {
    const StreamStatusMessage& s = msg.streams[i];
    posed_msgs_msg_dds__StreamStatus_& d = streams[i];
    d.name = c_str(s.name);
    d.rate_hz = s.rate_hz;
    d.received = s.received;
    d.decoded = s.decoded;
    d.dropped = s.dropped;
    d.malformed = s.malformed;
    d.clock_offset_ns = s.clock_offset_ns;
    d.clock_drift_ppm = s.clock_drift_ppm;
    d.clock_jitter_ns = s.clock_jitter_ns;
    d.clock_uncertainty_ns = s.clock_uncertainty_ns;
    d.clock_state = c_str(s.clock_state);
    d.health = c_str(s.health);
  }
  for (std::size_t i = 0; i < msg.latency.size(); ++i) {
    const TopicLatencyMessage& l = msg.latency[i];
    posed_msgs_msg_dds__TopicLatency_& d = out.latency[i];
    d.topic = c_str(l.topic);
    d.count = l.count;
    d.live = l.live;
    d.receive_to_write_p50_ms = l.receive_to_write_p50_ms;
    d.receive_to_write_p99_ms = l.receive_to_write_p99_ms;
    d.receive_to_write_max_ms = l.receive_to_write_max_ms;
    d.stamp_age_p50_ms = l.stamp_age_p50_ms;
    d.stamp_age_p99_ms = l.stamp_age_p99_ms;
    d.stamp_age_max_ms = l.stamp_age_max_ms;
  }
  const MappingStatusMessage& mapping = msg.mapping;
  out.mapping.state = c_str(mapping.state);
  out.mapping.keyframes = mapping.keyframes;
  out.mapping.loops = mapping.loops;
  out.mapping.fixes = mapping.fixes;
  out.mapping.correction_m = mapping.correction_m;
  out.mapping.scans_skipped = mapping.scans_skipped;
  out.streams._buffer = streams.data();
  out.streams._length = static_cast<std::uint32_t>(msg.streams.size());
  out.streams._maximum = static_cast<std::uint32_t>(streams.size());
  out.streams._release = false;  // the buffer belongs to the caller, not to Cyclone
}

void fill_tf(const TfMessage& msg, tf2_msgs_msg_dds__TFMessage_& out,
             std::vector<geometry_msgs_msg_dds__TransformStamped_>& transforms) {
  if (transforms.size() < msg.transforms.size()) transforms.resize(msg.transforms.size());
  for (std::size_t i = 0; i < msg.transforms.size(); ++i) {
    const TransformMessage& t = msg.transforms[i];
    geometry_msgs_msg_dds__TransformStamped_& d = transforms[i];
    d.header.stamp = to_ros_time(t.stamp);
    d.header.frame_id = c_str(t.parent_frame);
    d.child_frame_id = c_str(t.child_frame);
    d.transform.translation = {t.p_parent_child_m.x(), t.p_parent_child_m.y(),
                               t.p_parent_child_m.z()};
    d.transform.rotation = to_quaternion(t.q_parent_child);
  }
  out.transforms._buffer = transforms.data();
  out.transforms._length = static_cast<std::uint32_t>(msg.transforms.size());
  out.transforms._maximum = static_cast<std::uint32_t>(transforms.size());
  out.transforms._release = false;  // the buffer belongs to the caller, not to Cyclone
}

void fill_path(const PathMessage& msg, char* frame_id, nav_msgs_msg_dds__Path_& out,
               std::vector<geometry_msgs_msg_dds__PoseStamped_>& poses) {
  if (poses.size() < msg.poses.size()) poses.resize(msg.poses.size());
  for (std::size_t i = 0; i < msg.poses.size(); ++i) {
    fill_pose(msg.poses[i], poses[i]);
    poses[i].header.frame_id = frame_id;
  }
  out.header.stamp = to_ros_time(msg.stamp);
  out.header.frame_id = frame_id;
  out.poses._buffer = poses.data();
  out.poses._length = static_cast<std::uint32_t>(msg.poses.size());
  out.poses._maximum = static_cast<std::uint32_t>(poses.size());
  out.poses._release = false;  // the buffer belongs to the caller, not to Cyclone
}

void fill_diagnostics(const DiagnosticsMessage& msg, diagnostic_msgs_msg_dds__DiagnosticArray_& out,
                      std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_>& statuses,
                      std::vector<std::vector<diagnostic_msgs_msg_dds__KeyValue_>>& values) {
  if (statuses.size() < msg.status.size()) statuses.resize(msg.status.size());
  if (values.size() < msg.status.size()) values.resize(msg.status.size());
  for (std::size_t i = 0; i < msg.status.size(); ++i) {
    const DiagnosticStatusMessage& m = msg.status[i];
    diagnostic_msgs_msg_dds__DiagnosticStatus_& d = statuses[i];
    d.level = m.level;
    d.name = c_str(m.name);
    d.message = c_str(m.message);
    d.hardware_id = c_str(m.hardware_id);
    std::vector<diagnostic_msgs_msg_dds__KeyValue_>& kv = values[i];
    if (kv.size() < m.values.size()) kv.resize(m.values.size());
    for (std::size_t k = 0; k < m.values.size(); ++k) {
      kv[k].key = c_str(m.values[k].first);
      kv[k].value = c_str(m.values[k].second);
    }
    d.values._buffer = kv.data();
    d.values._length = static_cast<std::uint32_t>(m.values.size());
    d.values._maximum = static_cast<std::uint32_t>(kv.size());
    d.values._release = false;
  }
  out.header.stamp = to_ros_time(msg.stamp);
  out.status._buffer = statuses.data();
  out.status._length = static_cast<std::uint32_t>(msg.status.size());
  out.status._maximum = static_cast<std::uint32_t>(statuses.size());
  out.status._release = false;
}

void fill_cloud(const CloudMessage& msg, sensor_msgs_msg_dds__PointCloud2_& out,
                std::vector<sensor_msgs_msg_dds__PointField_>& fields) {
  if (fields.size() < msg.fields.size()) fields.resize(msg.fields.size());
  for (std::size_t i = 0; i < msg.fields.size(); ++i) {
    const PointFieldMessage& f = msg.fields[i];
    fields[i].name = c_str(f.name);
    fields[i].offset = f.offset;
    fields[i].datatype = f.datatype;
    fields[i].count = f.count;
  }
  out.header.stamp = to_ros_time(msg.stamp);
  out.header.frame_id = c_str(msg.frame_id);
  out.height = 1;
  out.width = msg.width;
  out.fields._buffer = fields.data();
  out.fields._length = static_cast<std::uint32_t>(msg.fields.size());
  out.fields._maximum = static_cast<std::uint32_t>(fields.size());
  out.fields._release = false;  // the buffers belong to the caller, not to Cyclone
  out.is_bigendian = false;
  out.point_step = msg.point_step;
  out.row_step = msg.point_step * msg.width;
  out.data._buffer = const_cast<std::uint8_t*>(msg.data.data());
  out.data._length = static_cast<std::uint32_t>(msg.data.size());
  out.data._maximum = static_cast<std::uint32_t>(msg.data.size());
  out.data._release = false;
  out.is_dense = msg.is_dense;
}

void fill_image(const ImageMessage& msg, sensor_msgs_msg_dds__CompressedImage_& out) {
  out.header.stamp = to_ros_time(msg.stamp);
  out.header.frame_id = c_str(msg.frame_id);
  out.format = c_str(msg.format);
  out.data._buffer = const_cast<std::uint8_t*>(msg.data.data());
  out.data._length = static_cast<std::uint32_t>(msg.data.size());
  out.data._maximum = static_cast<std::uint32_t>(msg.data.size());
  out.data._release = false;  // the buffer belongs to the caller, not to Cyclone
}

ImageMessage to_plain(const sensor_msgs_msg_dds__CompressedImage_& in) {
  ImageMessage msg;
  msg.stamp = from_ros_time(in.header.stamp);
  msg.frame_id = to_string(in.header.frame_id);
  msg.format = to_string(in.format);
  msg.data.assign(in.data._buffer, in.data._buffer + in.data._length);
  return msg;
}

CloudMessage to_plain(const sensor_msgs_msg_dds__PointCloud2_& in) {
  CloudMessage msg;
  msg.stamp = from_ros_time(in.header.stamp);
  msg.frame_id = to_string(in.header.frame_id);
  for (std::uint32_t i = 0; i < in.fields._length; ++i) {
    const sensor_msgs_msg_dds__PointField_& f = in.fields._buffer[i];
    msg.fields.push_back({to_string(f.name), f.offset, f.datatype, f.count});
  }
  msg.point_step = in.point_step;
  msg.width = in.width * std::max<std::uint32_t>(in.height, 1);
  msg.data.assign(in.data._buffer, in.data._buffer + in.data._length);
  msg.is_dense = in.is_dense;
  return msg;
}

PathMessage to_plain(const nav_msgs_msg_dds__Path_& in) {
  PathMessage msg;
  msg.stamp = from_ros_time(in.header.stamp);
  for (std::uint32_t i = 0; i < in.poses._length; ++i) {
    msg.poses.push_back(to_plain(in.poses._buffer[i]));
  }
  return msg;
}

DiagnosticsMessage to_plain(const diagnostic_msgs_msg_dds__DiagnosticArray_& in) {
  DiagnosticsMessage msg;
  msg.stamp = from_ros_time(in.header.stamp);
  for (std::uint32_t i = 0; i < in.status._length; ++i) {
    const diagnostic_msgs_msg_dds__DiagnosticStatus_& d = in.status._buffer[i];
    DiagnosticStatusMessage m;
    m.level = d.level;
    m.name = to_string(d.name);
    m.message = to_string(d.message);
    m.hardware_id = to_string(d.hardware_id);
    for (std::uint32_t k = 0; k < d.values._length; ++k) {
      m.values.emplace_back(to_string(d.values._buffer[k].key),
                            to_string(d.values._buffer[k].value));
    }
    msg.status.push_back(std::move(m));
  }
  return msg;
}

TfMessage to_plain(const tf2_msgs_msg_dds__TFMessage_& in) {
  TfMessage msg;
  for (std::uint32_t i = 0; i < in.transforms._length; ++i) {
    const geometry_msgs_msg_dds__TransformStamped_& s = in.transforms._buffer[i];
    TransformMessage t;
    t.stamp = from_ros_time(s.header.stamp);
    t.parent_frame = to_string(s.header.frame_id);
    t.child_frame = to_string(s.child_frame_id);
    t.p_parent_child_m = {s.transform.translation.x, s.transform.translation.y,
                          s.transform.translation.z};
    t.q_parent_child = from_quaternion(s.transform.rotation);
    msg.transforms.push_back(std::move(t));
  }
  return msg;
}

OdomMessage to_plain(const nav_msgs_msg_dds__Odometry_& in) {
  OdomMessage msg;
  msg.stamp = from_ros_time(in.header.stamp);
  msg.p_map_base_m = from_point(in.pose.pose.position);
  msg.q_map_base = from_quaternion(in.pose.pose.orientation);
  std::copy(std::begin(in.pose.covariance), std::end(in.pose.covariance),
            msg.pose_covariance.begin());
  msg.v_base_mps = from_vector(in.twist.twist.linear);
  msg.w_base_radps = from_vector(in.twist.twist.angular);
  std::copy(std::begin(in.twist.covariance), std::end(in.twist.covariance),
            msg.twist_covariance.begin());
  return msg;
}

PoseMessage to_plain(const geometry_msgs_msg_dds__PoseStamped_& in) {
  PoseMessage msg;
  msg.stamp = from_ros_time(in.header.stamp);
  msg.p_map_base_m = from_point(in.pose.position);
  msg.q_map_base = from_quaternion(in.pose.orientation);
  return msg;
}

StatusMessage to_plain(const posed_msgs_msg_dds__Status_& in) {
  StatusMessage msg;
  msg.stamp = from_ros_time(in.header.stamp);
  msg.version = to_string(in.version);
  msg.estimator_mode = to_string(in.estimator_mode);
  EstimatorStatusMessage& e = msg.estimator;
  e.scans_used = in.estimator.scans_used;
  e.scans_rejected = in.estimator.scans_rejected;
  e.scans_degenerate = in.estimator.scans_degenerate;
  e.scans_skipped = in.estimator.scans_skipped;
  e.reinitialisations = in.estimator.reinitialisations;
  e.keyframes = in.estimator.keyframes;
  e.degenerate_directions = in.estimator.degenerate_directions;
  for (int i = 0; i < 3; ++i) {
    e.gyro_bias_radps[i] = in.estimator.gyro_bias_radps[i];
    e.accel_bias_mps2[i] = in.estimator.accel_bias_mps2[i];
  }
  CameraStatusMessage& cam = msg.camera;
  cam.mode = to_string(in.camera.mode);
  cam.frames = in.camera.frames;
  cam.frames_unusable = in.camera.frames_unusable;
  cam.features = in.camera.features;
  cam.depth_associated = in.camera.depth_associated;
  cam.match_success_rate = in.camera.match_success_rate;
  for (std::size_t i = 0; i < 3; ++i) {
    cam.confidence[i] = in.camera.confidence[i];
    cam.omega[i] = in.camera.omega[i];
  }
  msg.modalities = to_string(in.modalities);
  for (std::size_t i = 0; i < 3; ++i) {
    const posed_msgs_msg_dds__VisualStreamStatus_& v = in.visual[i];
    VisualStreamStatusMessage& d = msg.visual[i];
    d.configured = v.configured;
    d.active = v.active;
    d.omega = v.omega;
    d.confidence = v.confidence;
    d.factors = v.factors;
    d.failed = v.failed;
    d.gated_out = v.gated_out;
    d.left = v.left;
    d.rejoined = v.rejoined;
    d.inliers = v.inliers;
    d.reprojection_rms_px = v.reprojection_rms_px;
    d.residual_median = v.residual_median;
    d.keyframe_factors = v.keyframe_factors;
    d.still = v.still;
  }
  msg.selection.lidar_visual_inertial = in.selection.lidar_visual_inertial;
  msg.selection.lidar_inertial = in.selection.lidar_inertial;
  msg.selection.visual_inertial = in.selection.visual_inertial;
  msg.selection.imu_only = in.selection.imu_only;
  msg.selection.threshold_m = in.selection.threshold_m;
  msg.uptime_s = in.uptime_s;
  msg.summary = to_string(in.summary);
  msg.streams.reserve(in.streams._length);
  for (std::uint32_t i = 0; i < in.streams._length; ++i) {
    const posed_msgs_msg_dds__StreamStatus_& s = in.streams._buffer[i];
    StreamStatusMessage d;
    d.name = to_string(s.name);
    d.rate_hz = s.rate_hz;
    d.received = s.received;
    d.decoded = s.decoded;
    d.dropped = s.dropped;
    d.malformed = s.malformed;
    d.clock_offset_ns = s.clock_offset_ns;
    d.clock_drift_ppm = s.clock_drift_ppm;
    d.clock_jitter_ns = s.clock_jitter_ns;
    d.clock_uncertainty_ns = s.clock_uncertainty_ns;
    d.clock_state = to_string(s.clock_state);
    d.health = to_string(s.health);
    msg.streams.push_back(std::move(d));
  }
  for (std::size_t i = 0; i < msg.latency.size(); ++i) {
    const posed_msgs_msg_dds__TopicLatency_& l = in.latency[i];
    TopicLatencyMessage& d = msg.latency[i];
    d.topic = to_string(l.topic);
    d.count = l.count;
    d.live = l.live;
    d.receive_to_write_p50_ms = l.receive_to_write_p50_ms;
    d.receive_to_write_p99_ms = l.receive_to_write_p99_ms;
    d.receive_to_write_max_ms = l.receive_to_write_max_ms;
    d.stamp_age_p50_ms = l.stamp_age_p50_ms;
    d.stamp_age_p99_ms = l.stamp_age_p99_ms;
    d.stamp_age_max_ms = l.stamp_age_max_ms;
  }
  MappingStatusMessage& mapping = msg.mapping;
  mapping.state = to_string(in.mapping.state);
  mapping.keyframes = in.mapping.keyframes;
  mapping.loops = in.mapping.loops;
  mapping.fixes = in.mapping.fixes;
  mapping.correction_m = in.mapping.correction_m;
  mapping.scans_skipped = in.mapping.scans_skipped;
  return msg;
}

std::string to_string(const char* text) {
  return text != nullptr ? std::string(text) : std::string();
}

}  // namespace posed::dds::detail
