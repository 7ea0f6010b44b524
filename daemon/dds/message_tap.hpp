#pragma once
// A second way out for what the Publisher writes: the same samples as ROS 2 CDR bytes, for the
// Foxglove WebSocket server and the recording (ros2msg channels next to the raw ones). The bytes
// are exactly what a ROS 2 node would put on the wire for the type, so Foxglove and ROS 2 tools
// decode them with the ros2msg schemas of drivers/recording/ros2_schemas.hpp.

#include <cstddef>
#include <span>

#include "core/time.hpp"
#include "daemon/dds/messages.hpp"

namespace posed::dds {

class MessageTap {
 public:
  virtual ~MessageTap() = default;
  /// Whether `topic` is wanted now; false spares the Publisher the serialisation. Called on the
  /// publishing thread before every write, so it must be cheap.
  virtual bool wants(Topic topic) const = 0;
  /// One written message: `cdr` is the 4-byte encapsulation header (00 01 00 00, CDR little
  /// endian) and the XCDR1 body, valid only during the call. `stamp` is the message's header
  /// stamp (wall clock). Called on the publishing thread, one topic from one thread at a time;
  /// must not block.
  virtual void deliver(Topic topic, WallTime stamp, std::span<const std::byte> cdr) = 0;
};

}  // namespace posed::dds
