#pragma once
// Internal to daemon/dds (and its tests): plain message structs <-> idlc-generated C samples.
// The fill_* functions write only what the plain struct carries; header.frame_id and
// child_frame_id belong to the Publisher, which fixes them at creation.

#include <string>
#include <vector>

#include "daemon/dds/generated_types.hpp"
#include "daemon/dds/messages.hpp"

namespace posed::dds::detail {

/// Wall time [ns since epoch] -> ROS Time (sec floor, 0 <= nanosec < 1e9).
builtin_interfaces_msg_dds__Time_ to_ros_time(WallTime stamp);
WallTime from_ros_time(const builtin_interfaces_msg_dds__Time_& time);

void fill_odom(const OdomMessage& msg, nav_msgs_msg_dds__Odometry_& out);
void fill_pose(const PoseMessage& msg, geometry_msgs_msg_dds__PoseStamped_& out);

/// Points out's strings into `msg` (valid while msg lives, unchanged) and its stream sequence
/// into `streams`, which grows only when a message has more streams than ever before.
void fill_status(const StatusMessage& msg, posed_msgs_msg_dds__Status_& out,
                 std::vector<posed_msgs_msg_dds__StreamStatus_>& streams);

/// Points out's transforms at `transforms` (grown as needed) and their strings into `msg`
/// (valid while msg lives, unchanged).
void fill_tf(const TfMessage& msg, tf2_msgs_msg_dds__TFMessage_& out,
             std::vector<geometry_msgs_msg_dds__TransformStamped_>& transforms);

/// Points out's poses at `poses` (grown as needed), each stamped and in `frame_id` (which must
/// outlive the write).
void fill_path(const PathMessage& msg, char* frame_id, nav_msgs_msg_dds__Path_& out,
               std::vector<geometry_msgs_msg_dds__PoseStamped_>& poses);

/// Points out's statuses at `statuses` and their key/values at `values` (one vector per status,
/// grown as needed), their strings into `msg` (valid while msg lives, unchanged).
void fill_diagnostics(const DiagnosticsMessage& msg, diagnostic_msgs_msg_dds__DiagnosticArray_& out,
                      std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_>& statuses,
                      std::vector<std::vector<diagnostic_msgs_msg_dds__KeyValue_>>& values);

/// Points out's fields at `fields` (grown as needed) and its strings and data into `msg` (valid
/// while msg lives, unchanged): a cloud is never copied on its way to Cyclone.
void fill_cloud(const CloudMessage& msg, sensor_msgs_msg_dds__PointCloud2_& out,
                std::vector<sensor_msgs_msg_dds__PointField_>& fields);

/// Points out's strings and data into `msg` (valid while msg lives, unchanged).
void fill_image(const ImageMessage& msg, sensor_msgs_msg_dds__CompressedImage_& out);

OdomMessage to_plain(const nav_msgs_msg_dds__Odometry_& in);
PoseMessage to_plain(const geometry_msgs_msg_dds__PoseStamped_& in);
StatusMessage to_plain(const posed_msgs_msg_dds__Status_& in);
TfMessage to_plain(const tf2_msgs_msg_dds__TFMessage_& in);
PathMessage to_plain(const nav_msgs_msg_dds__Path_& in);
DiagnosticsMessage to_plain(const diagnostic_msgs_msg_dds__DiagnosticArray_& in);
/// Copies the data bytes; a big-endian or organised (height > 1) cloud keeps its bytes as sent
/// with width = all points.
CloudMessage to_plain(const sensor_msgs_msg_dds__PointCloud2_& in);
ImageMessage to_plain(const sensor_msgs_msg_dds__CompressedImage_& in);

/// A C string field as std::string (Cyclone leaves unset strings null).
std::string to_string(const char* text);

}  // namespace posed::dds::detail
