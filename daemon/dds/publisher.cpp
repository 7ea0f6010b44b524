#include "daemon/dds/publisher.hpp"

#include <array>
#include <atomic>
#include <vector>

#include "daemon/dds/cdr.hpp"
#include "daemon/dds/convert.hpp"
#include "daemon/dds/message_tap.hpp"
#include "daemon/dds/participant.hpp"

namespace posed::dds {
namespace {

/// A TFMessage has no header of its own: its first transform's stamp stands for it.
WallTime first_stamp(const TfMessage& msg) {
  return msg.transforms.empty() ? WallTime{} : msg.transforms.front().stamp;
}

}  // namespace

struct Publisher::Impl {
  std::shared_ptr<detail::Participant> participant;
  /// writer per Topic (index = enum value); 0 for a topic the DdsConfig leaves off
  std::array<dds_entity_t, kAllTopics.size()> writers{};
  // Frame ids live here for the publisher's lifetime; the samples point into them.
  std::string map_frame;
  std::string odom_frame;
  std::string base_frame;
  nav_msgs_msg_dds__Odometry_ odom_sample{};
  geometry_msgs_msg_dds__PoseStamped_ pose_sample{};
  posed_msgs_msg_dds__Status_ status_sample{};
  std::vector<posed_msgs_msg_dds__StreamStatus_> status_streams;
  tf2_msgs_msg_dds__TFMessage_ tf_sample{};
  std::vector<geometry_msgs_msg_dds__TransformStamped_> tf_transforms;
  tf2_msgs_msg_dds__TFMessage_ tf_static_sample{};
  std::vector<geometry_msgs_msg_dds__TransformStamped_> tf_static_transforms;
  nav_msgs_msg_dds__Path_ path_sample{};
  std::vector<geometry_msgs_msg_dds__PoseStamped_> path_poses;
  diagnostic_msgs_msg_dds__DiagnosticArray_ diagnostics_sample{};
  std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_> diagnostics_statuses;
  std::vector<std::vector<diagnostic_msgs_msg_dds__KeyValue_>> diagnostics_values;
  sensor_msgs_msg_dds__PointCloud2_ cloud_sample{};
  std::vector<sensor_msgs_msg_dds__PointField_> cloud_fields;
  sensor_msgs_msg_dds__PointCloud2_ map_sample{};
  sensor_msgs_msg_dds__CompressedImage_ image_sample{};
  std::vector<sensor_msgs_msg_dds__PointField_> map_fields;
  std::atomic<std::uint64_t> write_failures{0};
  MessageTap* tap = nullptr;
  /// per topic: the last message as CDR, for the tap (its capacity is reused)
  std::array<std::vector<std::byte>, kAllTopics.size()> cdr;

  dds_entity_t& writer(Topic topic) { return writers[static_cast<std::size_t>(topic)]; }

  /// false (nothing sent) for a topic without a writer or a write Cyclone rejected. The tap
  /// gets the message after the DDS write, so it never delays a DDS reader.
  bool write(Topic topic, const void* sample, WallTime stamp) {
    if (writer(topic) == 0) return false;
    const bool ok = dds_write(writer(topic), sample) == DDS_RETCODE_OK;
    if (!ok) write_failures.fetch_add(1, std::memory_order_relaxed);
    if (tap != nullptr && tap->wants(topic)) {
      std::vector<std::byte>& bytes = cdr[static_cast<std::size_t>(topic)];
      detail::encode_cdr(topic, sample, bytes);
      tap->deliver(topic, stamp, bytes);
    }
    return ok;
  }
};

std::unique_ptr<Publisher> Publisher::create(const DdsConfig& config, std::string& error) {
  auto impl = std::make_unique<Impl>();
  impl->participant = detail::Participant::open(config, error);
  if (!impl->participant) return nullptr;
  const dds_entity_t participant = impl->participant->handle();

  const auto make_writer = [&](Topic topic) {
    const dds_entity_t t = detail::create_topic(participant, topic, error);
    if (t < 0) return false;
    dds_qos_t* qos = detail::make_topic_qos(topic);
    dds_entity_t& writer = impl->writer(topic);
    writer = dds_create_writer(participant, t, qos, nullptr);
    dds_delete_qos(qos);
    if (writer < 0) {
      error = detail::describe_error(std::string(topic_name(topic)) + ": create writer", writer);
      return false;
    }
    return true;
  };
  const bool ok =
      make_writer(Topic::kOdom) && make_writer(Topic::kPose) && make_writer(Topic::kStatus) &&
      (!config.tf || (make_writer(Topic::kTf) && make_writer(Topic::kTfStatic))) &&
      (!config.path || make_writer(Topic::kPath)) &&
      (!config.diagnostics || make_writer(Topic::kDiagnostics)) &&
      (!config.cloud || make_writer(Topic::kCloud)) && (!config.map || make_writer(Topic::kMap)) &&
      (!config.image || make_writer(Topic::kImage));
  if (!ok) return nullptr;  // ~Participant deletes whatever was created

  impl->map_frame = config.map_frame;
  impl->odom_frame = config.odom_frame;
  impl->base_frame = config.base_frame;
  char* map_frame = impl->map_frame.data();
  impl->odom_sample.header.frame_id = impl->odom_frame.data();
  impl->odom_sample.child_frame_id = impl->base_frame.data();
  impl->pose_sample.header.frame_id = map_frame;
  impl->status_sample.header.frame_id = map_frame;
  impl->diagnostics_sample.header.frame_id = map_frame;
  impl->status_streams.resize(8);  // posed has 4 sensors, some with 2 streams
  return std::unique_ptr<Publisher>(new Publisher(std::move(impl)));
}

Publisher::Publisher(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Publisher::~Publisher() = default;

bool Publisher::publish_odom(const OdomMessage& msg) {
  detail::fill_odom(msg, impl_->odom_sample);
  return impl_->write(Topic::kOdom, &impl_->odom_sample, msg.stamp);
}

bool Publisher::publish_pose(const PoseMessage& msg) {
  detail::fill_pose(msg, impl_->pose_sample);
  return impl_->write(Topic::kPose, &impl_->pose_sample, msg.stamp);
}

bool Publisher::publish_status(const StatusMessage& msg) {
  detail::fill_status(msg, impl_->status_sample, impl_->status_streams);
  return impl_->write(Topic::kStatus, &impl_->status_sample, msg.stamp);
}

bool Publisher::publish_tf(const TfMessage& msg) {
  detail::fill_tf(msg, impl_->tf_sample, impl_->tf_transforms);
  return impl_->write(Topic::kTf, &impl_->tf_sample, first_stamp(msg));
}

bool Publisher::publish_tf_static(const TfMessage& msg) {
  detail::fill_tf(msg, impl_->tf_static_sample, impl_->tf_static_transforms);
  return impl_->write(Topic::kTfStatic, &impl_->tf_static_sample, first_stamp(msg));
}

bool Publisher::publish_path(const PathMessage& msg) {
  detail::fill_path(msg, impl_->map_frame.data(), impl_->path_sample, impl_->path_poses);
  return impl_->write(Topic::kPath, &impl_->path_sample, msg.stamp);
}

bool Publisher::publish_diagnostics(const DiagnosticsMessage& msg) {
  detail::fill_diagnostics(msg, impl_->diagnostics_sample, impl_->diagnostics_statuses,
                           impl_->diagnostics_values);
  return impl_->write(Topic::kDiagnostics, &impl_->diagnostics_sample, msg.stamp);
}

bool Publisher::publish_cloud(const CloudMessage& msg) {
  detail::fill_cloud(msg, impl_->cloud_sample, impl_->cloud_fields);
  return impl_->write(Topic::kCloud, &impl_->cloud_sample, msg.stamp);
}

bool Publisher::publish_map(const CloudMessage& msg) {
  detail::fill_cloud(msg, impl_->map_sample, impl_->map_fields);
  return impl_->write(Topic::kMap, &impl_->map_sample, msg.stamp);
}

bool Publisher::publish_image(const ImageMessage& msg) {
  detail::fill_image(msg, impl_->image_sample);
  return impl_->write(Topic::kImage, &impl_->image_sample, msg.stamp);
}

void Publisher::set_tap(MessageTap* tap) { impl_->tap = tap; }

bool Publisher::wanted(Topic topic) const {
  if (!has_writer(topic)) return false;
  return matched_subscribers(topic) > 0 || (impl_->tap != nullptr && impl_->tap->wants(topic));
}

bool Publisher::has_writer(Topic topic) const {
  return impl_->writers[static_cast<std::size_t>(topic)] != 0;
}

std::uint32_t Publisher::matched_subscribers(Topic topic) const {
  const dds_entity_t writer = impl_->writers[static_cast<std::size_t>(topic)];
  if (writer == 0) return 0;
  dds_publication_matched_status_t status{};
  if (dds_get_publication_matched_status(writer, &status) != DDS_RETCODE_OK) return 0;
  return status.current_count;
}

std::uint64_t Publisher::write_failures() const {
  return impl_->write_failures.load(std::memory_order_relaxed);
}

std::shared_ptr<detail::Participant> Publisher::participant() const { return impl_->participant; }

}  // namespace posed::dds
