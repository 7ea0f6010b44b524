// The poses a recording holds on one topic, decoded and keyed by stamp: the replay tests read
// posed's own recordings (--record) and the simulator's ground truth through this.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <string>

#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/ros2_messages.hpp"

namespace posed::testing {

/// The messages of `topic` in a recording (nav_msgs/Odometry if `odometry`, else
/// geometry_msgs/PoseStamped), decoded, by stamp [ns].
inline std::map<std::int64_t, drivers::recording::ros2::StampedPose> recorded_poses(
    const std::string& path, const std::string& topic, bool odometry) {
  namespace rec = drivers::recording;
  rec::McapReader reader;
  std::string error;
  EXPECT_TRUE(reader.open(path, error)) << error;
  std::map<std::int64_t, rec::ros2::StampedPose> out;
  rec::McapMessage m;
  while (reader.next(m)) {
    if (m.channel->topic != topic) continue;
    rec::ros2::StampedPose p;
    const bool ok = odometry ? rec::ros2::decode_odometry(m.data, p)
                             : rec::ros2::decode_pose_stamped(m.data, p);
    EXPECT_TRUE(ok);
    out[p.stamp.ns] = p;
  }
  return out;
}

}  // namespace posed::testing
