#pragma once
// posed's DDS output (DESIGN.md, DDS interface): nav_msgs/Odometry on rt/posed/odom,
// geometry_msgs/PoseStamped on rt/posed/pose, posed_msgs/Status on rt/posed/status and
// tf2_msgs/TFMessage on rt/tf and rt/tf_static, nav_msgs/Path on rt/posed/path and
// diagnostic_msgs/DiagnosticArray on rt/diagnostics, sensor_msgs/PointCloud2 on rt/posed/cloud
// and rt/posed/map, with
// ROS 2's DDS type names, so `ros2 topic echo /posed/odom` or any plain DDS reader receives them.

#include <cstdint>
#include <memory>
#include <string>

#include "daemon/dds/messages.hpp"

namespace posed::dds {

class MessageTap;
namespace detail {
class Participant;
}

/// One DDS participant with a writer per topic. Publishing reuses preallocated samples (frame
/// ids fixed at creation), so it allocates nothing beyond what Cyclone does per write.
/// Thread-safety: each publish_* may run on its own thread, but one topic from one thread.
class Publisher {
 public:
  /// nullptr with `error` set (naming the Cyclone XML file when one is configured) on failure.
  static std::unique_ptr<Publisher> create(const DdsConfig& config, std::string& error);
  ~Publisher();
  Publisher(const Publisher&) = delete;
  Publisher& operator=(const Publisher&) = delete;

  /// false when Cyclone rejected the write (e.g. a reliable reader blocked it > 10 ms);
  /// such failures are also counted in write_failures().
  bool publish_odom(const OdomMessage& msg);
  bool publish_pose(const PoseMessage& msg);
  bool publish_status(const StatusMessage& msg);
  /// rt/tf (false, and nothing sent, when created without DdsConfig::tf).
  bool publish_tf(const TfMessage& msg);
  /// rt/tf_static, transient-local: the last message (all static transforms) reaches readers
  /// that join later.
  bool publish_tf_static(const TfMessage& msg);
  /// rt/posed/path in the map frame (false, nothing sent, when created without DdsConfig::path).
  bool publish_path(const PathMessage& msg);
  /// rt/diagnostics (false, nothing sent, when created without DdsConfig::diagnostics).
  bool publish_diagnostics(const DiagnosticsMessage& msg);

  /// rt/posed/cloud: one deskewed scan (false, nothing sent, without DdsConfig::cloud).
  bool publish_cloud(const CloudMessage& msg);
  /// rt/posed/map, transient-local (false, nothing sent, without DdsConfig::map).
  bool publish_map(const CloudMessage& msg);
  /// rt/posed/image/compressed (false, nothing sent, without DdsConfig::image).
  bool publish_image(const ImageMessage& msg);

  /// Hands every message written from now on to `tap` too, as ROS 2 CDR (MessageTap). Set it
  /// before the first publish_*; it must outlive the Publisher's writes. nullptr: none.
  void set_tap(MessageTap* tap);
  /// Whether a message on `topic` would reach anyone now: a matched DDS reader or the tap. Lets
  /// the caller skip building a costly message (a cloud) nobody reads.
  bool wanted(Topic topic) const;
  /// Whether the config gave `topic` a writer.
  bool has_writer(Topic topic) const;
  /// Readers currently matched on `topic` [count]; samples before a match are not delivered
  /// (volatile durability), so tests and benchmarks wait for this first.
  std::uint32_t matched_subscribers(Topic topic) const;
  /// Writes Cyclone rejected since creation [count].
  std::uint64_t write_failures() const;

  /// The participant the writers live on, for a reader in daemon/dds that shares it
  /// (InitialPoseReader::create): one participant per daemon, one discovery and one DDS Security
  /// handshake. It stays alive while either holds it.
  std::shared_ptr<detail::Participant> participant() const;

 private:
  struct Impl;
  explicit Publisher(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace posed::dds
