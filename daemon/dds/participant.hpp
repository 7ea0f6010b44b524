#pragma once
// Internal to daemon/dds: a DDS participant on the domain DdsConfig names, created from the
// configured Cyclone XML file when there is one, and the QoS every posed topic uses.

#include <dds/dds.h>

#include <memory>
#include <string>

#include "daemon/dds/messages.hpp"

namespace posed::dds::detail {

/// Owns one participant and a reference to its domain. Cyclone has one domain instance per id
/// and process, so a Publisher and a Subscriber in one process (posectl bench, tests) share it:
/// the domain is created from the XML by the first user and deleted when the last one goes.
class Participant {
 public:
  /// nullptr with `error` set (naming the XML file) when the domain or participant fails.
  static std::unique_ptr<Participant> open(const DdsConfig& config, std::string& error);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  dds_entity_t handle() const { return participant_; }

 private:
  Participant(dds_entity_t participant, std::uint32_t domain_id, bool holds_domain_ref);

  dds_entity_t participant_;
  std::uint32_t domain_id_;
  bool holds_domain_ref_;
};

/// QoS of a posed topic (DESIGN.md, DDS interface): reliable, volatile, keep-last 10, XCDR1
/// (the plain CDR ROS 2 uses); rt/tf_static transient-local, as ROS 2's static broadcaster, so a
/// late joiner gets the transforms. Caller deletes with dds_delete_qos.
dds_qos_t* make_topic_qos(Topic topic);

/// The idlc type descriptor of what `topic` carries (its name, size and serialisation ops).
const dds_topic_descriptor_t& descriptor(Topic topic);

/// Creates the topic `topic` of the type its descriptor names; error names the topic.
dds_entity_t create_topic(dds_entity_t participant, Topic topic, std::string& error);

/// QoS of rt/initialpose on both ends, as RViz's "2D Pose Estimate" tool publishes it
/// (rclcpp::QoS(5): reliable, volatile, keep-last 5), XCDR1. Caller deletes with dds_delete_qos.
dds_qos_t* make_initial_pose_qos();

/// Creates the topic `name` of geometry_msgs/PoseWithCovarianceStamped; error names the topic.
dds_entity_t create_initial_pose_topic(dds_entity_t participant, const std::string& name,
                                       std::string& error);

/// "<what>: <Cyclone's reason>", e.g. "rt/posed/odom: create writer: Bad parameter"
std::string describe_error(std::string_view what, dds_return_t rc);

}  // namespace posed::dds::detail
