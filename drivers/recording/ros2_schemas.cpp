#include "drivers/recording/ros2_schemas.hpp"

#include <initializer_list>
#include <string>

namespace posed::drivers::recording::ros2 {
namespace {

// The rosbag2 convention: the top-level definition, then each dependency after a line of 80 '='
// and "MSG: pkg/Type". A type named without its package is from the package it appears in.
constexpr std::string_view kSep =
    "================================================================================\n";

constexpr std::string_view kHeaderDef =
    "MSG: std_msgs/Header\n"
    "builtin_interfaces/Time stamp\n"
    "string frame_id\n";
constexpr std::string_view kTimeDef =
    "MSG: builtin_interfaces/Time\n"
    "int32 sec\n"
    "uint32 nanosec\n";
constexpr std::string_view kPoseStampedDef =
    "MSG: geometry_msgs/PoseStamped\n"
    "std_msgs/Header header\n"
    "Pose pose\n";
constexpr std::string_view kPoseDef =
    "MSG: geometry_msgs/Pose\n"
    "Point position\n"
    "Quaternion orientation\n";
constexpr std::string_view kPointDef =
    "MSG: geometry_msgs/Point\n"
    "float64 x\n"
    "float64 y\n"
    "float64 z\n";
constexpr std::string_view kQuaternionDef =
    "MSG: geometry_msgs/Quaternion\n"
    "float64 x 0\n"
    "float64 y 0\n"
    "float64 z 0\n"
    "float64 w 1\n";
constexpr std::string_view kVector3Def =
    "MSG: geometry_msgs/Vector3\n"
    "float64 x\n"
    "float64 y\n"
    "float64 z\n";

std::string join(std::initializer_list<std::string_view> parts) {
  std::string s;
  bool first = true;
  for (auto p : parts) {
    if (!first) s += kSep;
    s += p;
    first = false;
  }
  return s;
}

}  // namespace

std::string_view pose_stamped_schema() {
  static const std::string s =
      join({"# A Pose with reference coordinate frame and timestamp\n"
            "std_msgs/Header header\n"
            "Pose pose\n",
            kHeaderDef, kTimeDef, kPoseDef, kPointDef, kQuaternionDef});
  return s;
}

std::string_view odometry_schema() {
  static const std::string s =
      join({"# This represents an estimate of a position and velocity in free space.\n"
            "std_msgs/Header header\n"
            "string child_frame_id\n"
            "geometry_msgs/PoseWithCovariance pose\n"
            "geometry_msgs/TwistWithCovariance twist\n",
            kHeaderDef, kTimeDef,
            "MSG: geometry_msgs/PoseWithCovariance\n"
            "Pose pose\n"
            "float64[36] covariance\n",
            kPoseDef, kPointDef, kQuaternionDef,
            "MSG: geometry_msgs/TwistWithCovariance\n"
            "Twist twist\n"
            "float64[36] covariance\n",
            "MSG: geometry_msgs/Twist\n"
            "Vector3  linear\n"
            "Vector3  angular\n",
            kVector3Def});
  return s;
}

std::string_view tf_message_schema() {
  static const std::string s = join({"geometry_msgs/TransformStamped[] transforms\n",
                                     "MSG: geometry_msgs/TransformStamped\n"
                                     "std_msgs/Header header\n"
                                     "string child_frame_id\n"
                                     "Transform transform\n",
                                     kHeaderDef, kTimeDef,
                                     "MSG: geometry_msgs/Transform\n"
                                     "Vector3 translation\n"
                                     "Quaternion rotation\n",
                                     kVector3Def, kQuaternionDef});
  return s;
}

std::string_view path_schema() {
  static const std::string s =
      join({"# An array of poses that represents a Path for a robot to follow.\n"
            "std_msgs/Header header\n"
            "geometry_msgs/PoseStamped[] poses\n",
            kHeaderDef, kTimeDef, kPoseStampedDef, kPoseDef, kPointDef, kQuaternionDef});
  return s;
}

std::string_view diagnostic_array_schema() {
  static const std::string s =
      join({"std_msgs/Header header\n"
            "DiagnosticStatus[] status\n",
            kHeaderDef, kTimeDef,
            "MSG: diagnostic_msgs/DiagnosticStatus\n"
            "byte OK=0\n"
            "byte WARN=1\n"
            "byte ERROR=2\n"
            "byte STALE=3\n"
            "byte level\n"
            "string name\n"
            "string message\n"
            "string hardware_id\n"
            "KeyValue[] values\n",
            "MSG: diagnostic_msgs/KeyValue\n"
            "string key\n"
            "string value\n"});
  return s;
}

std::string_view point_cloud2_schema() {
  static const std::string s =
      join({"std_msgs/Header header\n"
            "uint32 height\n"
            "uint32 width\n"
            "PointField[] fields\n"
            "bool    is_bigendian\n"
            "uint32  point_step\n"
            "uint32  row_step\n"
            "uint8[] data\n"
            "bool is_dense\n",
            kHeaderDef, kTimeDef,
            "MSG: sensor_msgs/PointField\n"
            "uint8 INT8    = 1\n"
            "uint8 UINT8   = 2\n"
            "uint8 INT16   = 3\n"
            "uint8 UINT16  = 4\n"
            "uint8 INT32   = 5\n"
            "uint8 UINT32  = 6\n"
            "uint8 FLOAT32 = 7\n"
            "uint8 FLOAT64 = 8\n"
            "string name\n"
            "uint32 offset\n"
            "uint8  datatype\n"
            "uint32 count\n"});
  return s;
}

std::string_view posed_status_schema() {
  // daemon/dds/idl/posed_msgs.idl, field for field.
  static const std::string s =
      join({"std_msgs/Header header\n"
            "string version\n"
            "string estimator_mode\n"
            "EstimatorStatus estimator\n"
            "CameraStatus camera\n"
            "string modalities\n"
            "VisualStreamStatus[3] visual\n"
            "PoseSelectionStatus selection\n"
            "float64 uptime_s\n"
            "string summary\n"
            "StreamStatus[] streams\n"
            "TopicLatency[2] latency\n"
            "MappingStatus mapping\n",
            kHeaderDef, kTimeDef,
            "MSG: posed_msgs/EstimatorStatus\n"
            "uint64 scans_used\n"
            "uint64 scans_rejected\n"
            "uint64 scans_degenerate\n"
            "uint64 scans_skipped\n"
            "uint64 reinitialisations\n"
            "uint64 keyframes\n"
            "int32 degenerate_directions\n"
            "float64[3] gyro_bias_radps\n"
            "float64[3] accel_bias_mps2\n",
            "MSG: posed_msgs/CameraStatus\n"
            "string mode\n"
            "uint64 frames\n"
            "uint64 frames_unusable\n"
            "int32 features\n"
            "int32 depth_associated\n"
            "float64 match_success_rate\n"
            "float64[3] confidence\n"
            "float64[3] omega\n",
            "MSG: posed_msgs/VisualStreamStatus\n"
            "bool configured\n"
            "bool active\n"
            "float64 omega\n"
            "float64 confidence\n"
            "uint64 factors\n"
            "uint64 failed\n"
            "uint64 gated_out\n"
            "uint64 left\n"
            "uint64 rejoined\n"
            "int32 inliers\n"
            "float64 reprojection_rms_px\n"
            "float64 residual_median\n"
            "uint64 keyframe_factors\n"
            "int32 still\n",
            "MSG: posed_msgs/PoseSelectionStatus\n"
            "uint64 lidar_visual_inertial\n"
            "uint64 lidar_inertial\n"
            "uint64 visual_inertial\n"
            "uint64 imu_only\n"
            "float64 threshold_m\n",
            "MSG: posed_msgs/StreamStatus\n"
            "string name\n"
            "float64 rate_hz\n"
            "uint64 received\n"
            "uint64 decoded\n"
            "uint64 dropped\n"
            "uint64 malformed\n"
            "int64 clock_offset_ns\n"
            "float64 clock_drift_ppm\n"
            "float64 clock_jitter_ns\n"
            "float64 clock_uncertainty_ns\n"
            "string clock_state\n"
            "string health\n",
            "MSG: posed_msgs/TopicLatency\n"
            "string topic\n"
            "uint64 count\n"
            "bool live\n"
            "float64 receive_to_write_p50_ms\n"
            "float64 receive_to_write_p99_ms\n"
            "float64 receive_to_write_max_ms\n"
            "float64 stamp_age_p50_ms\n"
            "float64 stamp_age_p99_ms\n"
            "float64 stamp_age_max_ms\n",
            "MSG: posed_msgs/MappingStatus\n"
            "string state\n"
            "uint64 keyframes\n"
            "uint64 loops\n"
            "uint64 fixes\n"
            "float64 correction_m\n"
            "uint64 scans_skipped\n"});
  return s;
}

std::string_view compressed_image_schema() {
  static const std::string s =
      join({"std_msgs/Header header\n"
            "string format\n"
            "uint8[] data\n",
            kHeaderDef, kTimeDef});
  return s;
}

std::string_view schema_for(std::string_view type_name) {
  if (type_name == kPoseStampedName) return pose_stamped_schema();
  if (type_name == kOdometryName) return odometry_schema();
  if (type_name == kTfMessageName) return tf_message_schema();
  if (type_name == kPathName) return path_schema();
  if (type_name == kDiagnosticArrayName) return diagnostic_array_schema();
  if (type_name == kPointCloud2Name) return point_cloud2_schema();
  if (type_name == kPosedStatusName) return posed_status_schema();
  if (type_name == kCompressedImageName) return compressed_image_schema();
  return {};
}

}  // namespace posed::drivers::recording::ros2
