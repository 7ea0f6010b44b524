#include "daemon/dds/initial_pose_writer.hpp"

#include <algorithm>

#include "daemon/dds/convert.hpp"
#include "daemon/dds/participant.hpp"
#include "drivers/common/host_clock.hpp"

namespace posed::dds {

std::unique_ptr<InitialPoseWriter> InitialPoseWriter::create(const DdsConfig& config,
                                                             std::string& error) {
  if (config.initial_pose_topic.empty()) {
    error = "no initial pose topic configured";
    return nullptr;
  }
  std::unique_ptr<InitialPoseWriter> w(new InitialPoseWriter());
  w->topic_ = config.initial_pose_topic;
  w->participant_ = detail::Participant::open(config, error);
  if (!w->participant_) return nullptr;
  const dds_entity_t participant = w->participant_->handle();
  const dds_entity_t topic = detail::create_initial_pose_topic(participant, w->topic_, error);
  if (topic < 0) return nullptr;  // ~Participant deletes whatever was created
  dds_qos_t* qos = detail::make_initial_pose_qos();
  w->writer_ = dds_create_writer(participant, topic, qos, nullptr);
  dds_delete_qos(qos);
  if (w->writer_ < 0) {
    error = detail::describe_error(w->topic_ + ": create writer", w->writer_);
    return nullptr;
  }
  // Wake wait_for_reader when a reader matches rather than polling.
  w->waitset_ = dds_create_waitset(participant);
  dds_return_t rc = w->waitset_;
  if (rc >= 0) rc = dds_set_status_mask(w->writer_, DDS_PUBLICATION_MATCHED_STATUS);
  if (rc >= 0) rc = dds_waitset_attach(w->waitset_, w->writer_, w->writer_);
  if (rc < 0) {
    error = detail::describe_error(w->topic_ + ": wait for readers", rc);
    return nullptr;
  }
  return w;
}

InitialPoseWriter::~InitialPoseWriter() = default;  // ~Participant deletes writer and waitset

bool InitialPoseWriter::wait_for_reader(Duration timeout) {
  const HostTime deadline = drivers::host_now() + timeout;
  for (;;) {
    if (matched_subscribers() > 0) return true;
    const Duration left = deadline - drivers::host_now();
    if (left.ns <= 0) return false;
    dds_waitset_wait(waitset_, nullptr, 0, left.ns);
  }
}

std::uint32_t InitialPoseWriter::matched_subscribers() const {
  dds_publication_matched_status_t status{};
  if (dds_get_publication_matched_status(writer_, &status) != DDS_RETCODE_OK) return 0;
  return status.current_count;
}

bool InitialPoseWriter::publish(const InitialPose& pose, std::string& error) {
  geometry_msgs_msg_dds__PoseWithCovarianceStamped_ sample{};
  sample.header.stamp = detail::to_ros_time(WallTime::from_ns(pose.stamp_ns));
  // Cyclone only reads the string during dds_write.
  sample.header.frame_id = const_cast<char*>(pose.frame_id.c_str());
  const Eigen::Vector3d p = pose.T_frame_base.translation();
  const Eigen::Quaterniond q(pose.T_frame_base.linear());
  sample.pose.pose.position = {p.x(), p.y(), p.z()};
  sample.pose.pose.orientation = {q.x(), q.y(), q.z(), q.w()};
  std::copy(pose.covariance.begin(), pose.covariance.end(), sample.pose.covariance);
  const dds_return_t rc = dds_write(writer_, &sample);
  if (rc != DDS_RETCODE_OK) {
    error = detail::describe_error(topic_ + ": write", rc);
    return false;
  }
  return true;
}

bool InitialPoseWriter::wait_acknowledged(Duration timeout) {
  return dds_wait_for_acks(writer_, timeout.ns) == DDS_RETCODE_OK;
}

}  // namespace posed::dds
