#pragma once
// ros2msg definitions of the ROS 2 types posed writes, for MCAP schemas (recordings) and
// Foxglove WebSocket channels: the text rosbag2 stores, so Foxglove, PlotJuggler and ROS 2 tools
// decode the CDR. Each must match the IDL in daemon/dds/idl/ field for field (tests compare).

#include <string_view>

namespace posed::drivers::recording::ros2 {

inline constexpr std::string_view kSchemaEncoding = "ros2msg";
inline constexpr std::string_view kMessageEncoding = "cdr";

inline constexpr std::string_view kPoseStampedName = "geometry_msgs/msg/PoseStamped";
inline constexpr std::string_view kOdometryName = "nav_msgs/msg/Odometry";
inline constexpr std::string_view kTfMessageName = "tf2_msgs/msg/TFMessage";
inline constexpr std::string_view kPathName = "nav_msgs/msg/Path";
inline constexpr std::string_view kDiagnosticArrayName = "diagnostic_msgs/msg/DiagnosticArray";
inline constexpr std::string_view kPointCloud2Name = "sensor_msgs/msg/PointCloud2";
inline constexpr std::string_view kPosedStatusName = "posed_msgs/msg/Status";
inline constexpr std::string_view kCompressedImageName = "sensor_msgs/msg/CompressedImage";

/// Full ros2msg definition (the type, then each dependency after a `===` line and `MSG: type`).
std::string_view pose_stamped_schema();
std::string_view odometry_schema();
std::string_view tf_message_schema();
std::string_view path_schema();
std::string_view diagnostic_array_schema();
std::string_view point_cloud2_schema();
std::string_view posed_status_schema();
std::string_view compressed_image_schema();

/// The definition of `type_name` (one of the k*Name above); empty for a type posed does not
/// write.
std::string_view schema_for(std::string_view type_name);

}  // namespace posed::drivers::recording::ros2
