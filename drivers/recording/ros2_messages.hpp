#pragma once
// ROS 2 messages as CDR bytes, written by hand so recordings plot in Foxglove, PlotJuggler and
// ROS 2 tools (MCAP message_encoding "cdr", schema encoding "ros2msg"). CDR here is XCDR1 as ROS 2
// (rmw_cyclonedds/fastrtps) emits it: a 4-byte encapsulation header 00 01 00 00 (CDR_LE), then
// fields in order, each primitive aligned to its own size relative to the byte after the
// encapsulation header; strings are u32 length including the NUL, the bytes, the NUL.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/time.hpp"
#include "drivers/recording/ros2_schemas.hpp"

namespace posed::drivers::recording::ros2 {

/// A pose with its header, as TUM export needs it.
struct StampedPose {
  /// header.stamp [ns since the UNIX epoch]
  WallTime stamp;
  std::string frame_id;
  /// position [m]
  std::array<double, 3> p_xyz_m{};
  /// orientation quaternion, ROS order x, y, z, w
  std::array<double, 4> q_xyzw{0, 0, 0, 1};
};

/// geometry_msgs/msg/PoseStamped.
void encode_pose_stamped(const StampedPose& pose, std::vector<std::byte>& out);
/// nav_msgs/msg/Odometry with zero covariances; twist in the child frame [m/s], [rad/s].
void encode_odometry(const StampedPose& pose, std::string_view child_frame_id,
                     const std::array<double, 3>& v_mps, const std::array<double, 3>& w_radps,
                     std::vector<std::byte>& out);

/// Decoders for export; false on bytes that are not a complete message of that type.
bool decode_pose_stamped(std::span<const std::byte> cdr, StampedPose& out);
bool decode_odometry(std::span<const std::byte> cdr, StampedPose& out,
                     std::string* child_frame_id = nullptr);

}  // namespace posed::drivers::recording::ros2
