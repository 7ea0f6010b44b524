#pragma once
// Reads posed's DDS topics back into the plain structs of messages.hpp: for posectl echo, the
// DDS benchmark and the tests. Not used by the daemon itself.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/time.hpp"
#include "daemon/dds/messages.hpp"

namespace posed::dds {

/// One received sample with the header strings and when it was taken from the reader.
template <class Message>
struct Received {
  Message msg;
  /// header.frame_id as sent
  std::string frame_id;
  /// child_frame_id (odometry only; empty otherwise)
  std::string child_frame_id;
  /// wall clock when taken from the reader, comparable with msg.stamp [ns]
  WallTime received_wall;
  /// host monotonic clock when taken from the reader [ns]
  HostTime received_host;
};

/// One participant with a reader per requested topic, same QoS as the Publisher.
/// Not thread-safe: one thread waits and takes.
class Subscriber {
 public:
  /// nullptr with `error` set on failure. `topics` empty means posed's three (odom, pose,
  /// status).
  static std::unique_ptr<Subscriber> create(const DdsConfig& config, std::span<const Topic> topics,
                                            std::string& error);
  ~Subscriber();
  Subscriber(const Subscriber&) = delete;
  Subscriber& operator=(const Subscriber&) = delete;

  /// Blocks until a sample waits on any subscribed topic (true) or `timeout` passes (false).
  bool wait(Duration timeout);

  /// Append every waiting sample of the topic to `out`; return how many [count]. A topic not
  /// subscribed yields 0.
  std::size_t take_odom(std::vector<Received<OdomMessage>>& out);
  std::size_t take_pose(std::vector<Received<PoseMessage>>& out);
  std::size_t take_status(std::vector<Received<StatusMessage>>& out);
  /// rt/tf or rt/tf_static (`topic`); the frames are in each transform.
  std::size_t take_tf(Topic topic, std::vector<Received<TfMessage>>& out);
  std::size_t take_path(std::vector<Received<PathMessage>>& out);
  std::size_t take_diagnostics(std::vector<Received<DiagnosticsMessage>>& out);
  /// rt/posed/cloud or rt/posed/map (`topic`).
  std::size_t take_cloud(Topic topic, std::vector<Received<CloudMessage>>& out);
  std::size_t take_image(std::vector<Received<ImageMessage>>& out);

  /// Writers currently matched on `topic` [count].
  std::uint32_t matched_publishers(Topic topic) const;

 private:
  struct Impl;
  explicit Subscriber(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace posed::dds
