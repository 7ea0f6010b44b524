#pragma once
// What posed publishes over DDS, as plain C++ structs the daemon fills. They mirror the IDL in
// daemon/dds/idl/ (ROS 2 nav_msgs/Odometry, geometry_msgs/PoseStamped, posed_msgs/Status) but do
// not depend on the generated C code, so the pipeline never includes a DDS header.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/time.hpp"

namespace posed::dds {

/// The topics posed publishes.
enum class Topic {
  kOdom,
  kPose,
  kStatus,
  kTf,
  kTfStatic,
  kPath,
  kDiagnostics,
  kCloud,
  kMap,
  kImage
};
/// Topics whose newest message a reader that joins later still gets: transient-local on DDS
/// (tf2's static broadcaster QoS; the map as map servers publish it), latched on Foxglove.
constexpr bool transient_local(Topic topic) {
  return topic == Topic::kTfStatic || topic == Topic::kMap;
}
/// Topics whose messages are large (point clouds, images): few are queued.
constexpr bool large_messages(Topic topic) {
  return topic == Topic::kCloud || topic == Topic::kMap || topic == Topic::kImage;
}
inline constexpr std::array kAllTopics = {
    Topic::kOdom, Topic::kPose,        Topic::kStatus, Topic::kTf,  Topic::kTfStatic,
    Topic::kPath, Topic::kDiagnostics, Topic::kCloud,  Topic::kMap, Topic::kImage};

/// DDS topic names: ROS 2 prefixes topics with "rt/", so ROS sees /posed/odom, /tf etc.
inline constexpr std::string_view kOdomTopic = "rt/posed/odom";
inline constexpr std::string_view kPoseTopic = "rt/posed/pose";
inline constexpr std::string_view kStatusTopic = "rt/posed/status";
inline constexpr std::string_view kTfTopic = "rt/tf";
inline constexpr std::string_view kTfStaticTopic = "rt/tf_static";
inline constexpr std::string_view kPathTopic = "rt/posed/path";
inline constexpr std::string_view kDiagnosticsTopic = "rt/diagnostics";
inline constexpr std::string_view kCloudTopic = "rt/posed/cloud";
inline constexpr std::string_view kMapTopic = "rt/posed/map";
/// image_transport's name for the compressed form of the image /posed/image
inline constexpr std::string_view kImageTopic = "rt/posed/image/compressed";

/// The DDS topic name of `topic`, e.g. "rt/posed/odom".
constexpr std::string_view topic_name(Topic topic) {
  switch (topic) {
    case Topic::kOdom:
      return kOdomTopic;
    case Topic::kPose:
      return kPoseTopic;
    case Topic::kStatus:
      return kStatusTopic;
    case Topic::kTf:
      return kTfTopic;
    case Topic::kTfStatic:
      return kTfStaticTopic;
    case Topic::kPath:
      return kPathTopic;
    case Topic::kDiagnostics:
      return kDiagnosticsTopic;
    case Topic::kCloud:
      return kCloudTopic;
    case Topic::kMap:
      return kMapTopic;
    case Topic::kImage:
      return kImageTopic;
  }
  return {};
}

/// The ROS 2 type `topic` carries, e.g. "nav_msgs/msg/Odometry" (the ros2msg schema name).
constexpr std::string_view ros_type_name(Topic topic) {
  switch (topic) {
    case Topic::kOdom:
      return "nav_msgs/msg/Odometry";
    case Topic::kPose:
      return "geometry_msgs/msg/PoseStamped";
    case Topic::kStatus:
      return "posed_msgs/msg/Status";
    case Topic::kTf:
    case Topic::kTfStatic:
      return "tf2_msgs/msg/TFMessage";
    case Topic::kPath:
      return "nav_msgs/msg/Path";
    case Topic::kDiagnostics:
      return "diagnostic_msgs/msg/DiagnosticArray";
    case Topic::kCloud:
    case Topic::kMap:
      return "sensor_msgs/msg/PointCloud2";
    case Topic::kImage:
      return "sensor_msgs/msg/CompressedImage";
  }
  return {};
}

/// The ROS 2 name of `topic` ("/posed/odom", "/tf"): the DDS name without ROS's "rt" prefix.
constexpr std::string_view ros_topic_name(Topic topic) { return topic_name(topic).substr(2); }

/// Accepts the DDS name ("rt/posed/odom", "rt/tf"), the ROS name ("/posed/odom", "/tf") or the
/// last part ("odom", "tf_static"; "image" for rt/posed/image/compressed).
constexpr bool parse_topic(std::string_view text, Topic& topic) {
  for (Topic t : kAllTopics) {
    const std::string_view full = topic_name(t);
    const std::string_view ros = full.substr(2);
    const std::string_view short_name =
        t == Topic::kImage ? "image" : full.substr(full.rfind('/') + 1);
    if (text == full || text == ros || text == short_name) {
      topic = t;
      return true;
    }
  }
  return false;
}

/// nav_msgs/Odometry: pose of base in map, twist of base expressed in base (ROS convention).
struct OdomMessage {
  /// time the state refers to (wall clock, UNIX epoch) [ns]
  WallTime stamp;
  /// position of the base frame origin in the map frame [m]
  Eigen::Vector3d p_map_base_m = Eigen::Vector3d::Zero();
  /// orientation of the base frame in the map frame (rotates base vectors into map) [-]
  Eigen::Quaterniond q_map_base = Eigen::Quaterniond::Identity();
  /// linear velocity of the base, expressed in the base (child) frame [m/s]
  Eigen::Vector3d v_base_mps = Eigen::Vector3d::Zero();
  /// angular velocity of the base, expressed in the base (child) frame [rad/s]
  Eigen::Vector3d w_base_radps = Eigen::Vector3d::Zero();
  /// row-major 6x6 over (x, y, z, rot x, rot y, rot z) [m^2, m*rad, rad^2]
  std::array<double, 36> pose_covariance{};
  /// row-major 6x6 over (vx, vy, vz, wx, wy, wz) [(m/s)^2, m/s*rad/s, (rad/s)^2]
  std::array<double, 36> twist_covariance{};
};

/// geometry_msgs/PoseStamped in the map frame.
struct PoseMessage {
  /// time the pose refers to (wall clock, UNIX epoch) [ns]
  WallTime stamp;
  /// position of the base frame origin in the map frame [m]
  Eigen::Vector3d p_map_base_m = Eigen::Vector3d::Zero();
  /// orientation of the base frame in the map frame [-]
  Eigen::Quaterniond q_map_base = Eigen::Quaterniond::Identity();
};

/// geometry_msgs/TransformStamped: the pose of `child_frame` in `parent_frame` (tf2's sense: it
/// maps points from the child frame into the parent frame).
struct TransformMessage {
  /// time the transform refers to (wall clock, UNIX epoch) [ns]; any time for a static one
  WallTime stamp;
  std::string parent_frame;
  std::string child_frame;
  /// position of the child frame's origin in the parent frame [m]
  Eigen::Vector3d p_parent_child_m = Eigen::Vector3d::Zero();
  /// orientation of the child frame in the parent frame [-]
  Eigen::Quaterniond q_parent_child = Eigen::Quaterniond::Identity();
};

/// tf2_msgs/TFMessage: what rt/tf and rt/tf_static carry.
struct TfMessage {
  std::vector<TransformMessage> transforms;
};

/// nav_msgs/Path in the map frame: the trajectory so far, oldest first.
struct PathMessage {
  /// time of the newest pose (wall clock, UNIX epoch) [ns]
  WallTime stamp;
  std::vector<PoseMessage> poses;
};

/// diagnostic_msgs/DiagnosticStatus: one component's health, as ROS 2's diagnostic tools read it.
struct DiagnosticStatusMessage {
  enum Level : std::uint8_t { kOk = 0, kWarn = 1, kError = 2, kStale = 3 };
  std::uint8_t level = kOk;
  std::string name;  ///< "posed: imu"; the aggregator groups by the prefix
  std::string message;
  std::string hardware_id;
  std::vector<std::pair<std::string, std::string>> values;  ///< key, value (with its unit)
};

/// diagnostic_msgs/DiagnosticArray.
struct DiagnosticsMessage {
  WallTime stamp;
  std::vector<DiagnosticStatusMessage> status;
};

/// sensor_msgs/PointField: one field of every point in a CloudMessage.
struct PointFieldMessage {
  /// PointField's datatype constants
  enum Type : std::uint8_t {
    kInt8 = 1,
    kUint8 = 2,
    kInt16 = 3,
    kUint16 = 4,
    kInt32 = 5,
    kUint32 = 6,
    kFloat32 = 7,
    kFloat64 = 8
  };
  std::string name;          ///< e.g. "x", "intensity", "ring"
  std::uint32_t offset = 0;  ///< from the start of the point [B]
  std::uint8_t datatype = kFloat32;
  std::uint32_t count = 1;  ///< elements [1]
};

/// sensor_msgs/PointCloud2, unordered (height 1), little-endian: rt/posed/cloud, rt/posed/map.
struct CloudMessage {
  /// time the points refer to (wall clock, UNIX epoch) [ns]
  WallTime stamp;
  std::string frame_id;
  std::vector<PointFieldMessage> fields;
  std::uint32_t point_step = 0;  ///< bytes per point [B]
  std::uint32_t width = 0;       ///< points [1]
  /// width * point_step bytes
  std::vector<std::uint8_t> data;
  /// no point has a non-finite coordinate
  bool is_dense = true;
};

/// sensor_msgs/CompressedImage: rt/posed/image/compressed.
struct ImageMessage {
  /// time the image was taken (wall clock, UNIX epoch) [ns]
  WallTime stamp;
  std::string frame_id;
  std::string format;  ///< "jpeg"
  std::vector<std::uint8_t> data;
};

/// posed_msgs/StreamStatus: health of one input stream.
struct StreamStatusMessage {
  /// stream name, e.g. "imu", "lidar"
  std::string name;
  /// measured arrival rate of decoded samples [Hz]
  double rate_hz = 0.0;
  /// samples received from the Source since start [count]
  std::uint64_t received = 0;
  /// samples decoded successfully since start [count]
  std::uint64_t decoded = 0;
  /// samples dropped by a queue's drop policy since start [count]
  std::uint64_t dropped = 0;
  /// samples the decoder rejected since start [count]
  std::uint64_t malformed = 0;
  /// host monotonic minus device clock, as estimated by ClockSync [ns]
  std::int64_t clock_offset_ns = 0;
  /// device clock rate error relative to the host clock [ppm]
  double clock_drift_ppm = 0.0;
  /// standard deviation of transport jitter around the clock model [ns]
  double clock_jitter_ns = 0.0;
  /// 1-sigma uncertainty of the mapped host time [ns]
  double clock_uncertainty_ns = 0.0;
  /// ClockSync state, e.g. "locked", "converging"
  std::string clock_state;
  /// overall verdict, e.g. "ok", "degraded", "stale"
  std::string health;
};

/// posed_msgs/EstimatorStatus: the estimator's figures.
struct EstimatorStatusMessage {
  std::uint64_t scans_used = 0;                               ///< [count]
  std::uint64_t scans_rejected = 0;                           ///< [count]
  std::uint64_t scans_degenerate = 0;                         ///< [count]
  std::uint64_t scans_skipped = 0;                            ///< [count]
  std::uint64_t reinitialisations = 0;                        ///< [count]
  std::uint64_t keyframes = 0;                                ///< [count]
  std::int32_t degenerate_directions = 0;                     ///< in the last scan match [count]
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();  ///< [rad/s]
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();  ///< [m/s^2]
};

/// posed_msgs/CameraStatus: the camera front end's figures.
struct CameraStatusMessage {
  std::string mode;                    ///< "visible", "thermal", "fused"; empty: none
  std::uint64_t frames = 0;            ///< [count]
  std::uint64_t frames_unusable = 0;   ///< [count]
  std::int32_t features = 0;           ///< in the last frame [count]
  std::int32_t depth_associated = 0;   ///< in the last frame [count]
  double match_success_rate = 0;       ///< since start [0..1]
  std::array<double, 3> confidence{};  ///< visible, thermal, fused in the last frame [0..1]
  std::array<double, 3> omega{};       ///< visible, thermal, fused in the last frame [-]
};

/// posed_msgs/VisualStreamStatus: one camera stream in the estimate.
struct VisualStreamStatusMessage {
  bool configured = false;
  bool active = false;                 ///< gate open
  double omega = 0;                    ///< [-]
  double confidence = 0;               ///< [0..1]
  std::uint64_t factors = 0;           ///< [count]
  std::uint64_t failed = 0;            ///< [count]
  std::uint64_t gated_out = 0;         ///< [count]
  std::uint64_t left = 0;              ///< [count]
  std::uint64_t rejoined = 0;          ///< [count]
  std::int32_t inliers = 0;            ///< [count]
  double reprojection_rms_px = 0;      ///< [px]
  double residual_median = 0;          ///< [sigma]
  std::uint64_t keyframe_factors = 0;  ///< [count]
  std::int32_t still = 0;              ///< [count]
};

/// posed_msgs/PoseSelectionStatus: seed 001's choices of initial value.
struct PoseSelectionStatusMessage {
  std::uint64_t lidar_visual_inertial = 0;  ///< [count]
  std::uint64_t lidar_inertial = 0;         ///< [count]
  std::uint64_t visual_inertial = 0;        ///< [count]
  std::uint64_t imu_only = 0;               ///< [count]
  double threshold_m = 0;                   ///< [m]
};

/// How late one published topic is (posed_msgs/TopicLatency), since start.
struct TopicLatencyMessage {
  std::string topic;  ///< e.g. "rt/posed/odom"; empty: unused slot
  std::uint64_t count = 0;
  /// stamps on this host's clock now; false: a replay's recorded stamps, all figures zero
  bool live = false;
  /// newest sample's host receive -> DDS write [ms]
  double receive_to_write_p50_ms = 0, receive_to_write_p99_ms = 0, receive_to_write_max_ms = 0;
  /// message stamp -> DDS write [ms]
  double stamp_age_p50_ms = 0, stamp_age_p99_ms = 0, stamp_age_max_ms = 0;
};

/// posed_msgs/MappingStatus: the mapping stage's figures.
struct MappingStatusMessage {
  /// "off" (no mapping stage), "mapping", or localising: "aligning", "localised", "lost"
  std::string state = "off";
  std::uint64_t keyframes = 0;      ///< closing loops: in the pose graph [count]
  std::uint64_t loops = 0;          ///< closing loops: accepted [count]
  std::uint64_t fixes = 0;          ///< localising: verified registrations onto the map [count]
  double correction_m = 0;          ///< map -> odom's translation [m]
  std::uint64_t scans_skipped = 0;  ///< live: kept from the stage by its full queue [count]
};

/// posed_msgs/Status: published at 1 Hz.
struct StatusMessage {
  /// time of the report (wall clock, UNIX epoch) [ns]
  WallTime stamp;
  /// daemon version, e.g. "posed 0.1.0"
  std::string version;
  /// estimator mode, e.g. "strapdown", "lidar_inertial"
  std::string estimator_mode;
  EstimatorStatusMessage estimator;
  CameraStatusMessage camera;
  /// what entered the estimate at the last state, e.g. "imu+lidar+visible"
  std::string modalities;
  /// visible, thermal, fused
  std::array<VisualStreamStatusMessage, 3> visual{};
  PoseSelectionStatusMessage selection;
  /// time since the daemon started [s]
  double uptime_s = 0.0;
  /// one-line human-readable summary
  std::string summary;
  /// one entry per input stream
  std::vector<StreamStatusMessage> streams;
  /// rt/posed/odom, rt/posed/pose
  std::array<TopicLatencyMessage, 2> latency{};
  MappingStatusMessage mapping;
};

/// DDS Security (OMG DDS Security 1.1 with Cyclone DDS's builtin plugins): the six files of a
/// participant's identity and permissions, as SROS2 names them in an enclave directory. All empty:
/// plain DDS.
struct DdsSecurityFiles {
  std::string identity_ca;           ///< identity_ca.cert.pem: CA that signed every identity
  std::string identity_certificate;  ///< cert.pem: this participant's certificate
  std::string private_key;           ///< key.pem: its private key
  std::string permissions_ca;        ///< permissions_ca.cert.pem: CA that signed the documents
  std::string governance;            ///< governance.p7s: the domain's protection rules, signed
  std::string permissions;           ///< permissions.p7s: what this participant may do, signed
  bool enabled() const { return !identity_certificate.empty(); }
  /// The files of SROS2's enclave directory `dir` (…/enclaves/NAME).
  static DdsSecurityFiles from_enclave(const std::string& dir);
};

/// Where and how posed talks DDS (the `dds:` section of the daemon config).
struct DdsConfig {
  /// DDS domain (ROS_DOMAIN_ID) [-]
  std::uint32_t domain_id = 0;
  /// header.frame_id of pose, path and status
  std::string map_frame = "map";
  /// rt/posed/odom's frame: odometry stays continuous in odom, loops move map -> odom (REP-105)
  std::string odom_frame = "odom";
  /// child_frame_id of odom
  std::string base_frame = "base_link";
  /// Cyclone XML file used to create the domain; empty: CYCLONEDDS_URI or Cyclone's default.
  std::string cyclonedds_xml_path;
  /// create writers for rt/tf and rt/tf_static (publish.tf)
  bool tf = true;
  /// create a writer for rt/posed/path (publish.path)
  bool path = true;
  /// create a writer for rt/diagnostics (publish.diagnostics)
  bool diagnostics = true;
  /// create a writer for rt/posed/cloud (publish.cloud)
  bool cloud = true;
  /// create a writer for rt/posed/map (publish.map)
  bool map = true;
  /// create a writer for rt/posed/image/compressed (publish.image)
  bool image = true;
  /// DDS topic the initial pose is read from (InitialPoseReader, dds.initialpose_topic), as
  /// RViz's 2D Pose Estimate publishes /initialpose; empty: none read
  std::string initial_pose_topic = "rt/initialpose";
  /// DDS Security; empty files: none
  DdsSecurityFiles security;
};

}  // namespace posed::dds
