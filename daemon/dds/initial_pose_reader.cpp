#include "daemon/dds/initial_pose_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <type_traits>

#include "daemon/dds/convert.hpp"
#include "daemon/dds/participant.hpp"
#include "daemon/dds/publisher.hpp"
#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"

namespace posed::dds {
namespace {

static_assert(std::is_same_v<dds_entity_t, std::int32_t>, "the header stores entities as int32");

using Sample = geometry_msgs_msg_dds__PoseWithCovarianceStamped_;

/// A normalised quaternion is within 1e-3 of unit length; RViz's (from a yaw) is exact.
constexpr double kUnitTolerance = 1e-3;
/// At most one refusal line this often, so a misbehaving publisher cannot flood the journal.
constexpr Duration kLogInterval = Duration::from_s(5);

/// Why `s` is refused, or empty when it is good.
std::string fault_of(const Sample& s) {
  const auto& p = s.pose.pose.position;
  const auto& q = s.pose.pose.orientation;
  char text[160];
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    std::snprintf(text, sizeof text, "non-finite position (%g, %g, %g)", p.x, p.y, p.z);
    return text;
  }
  if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) || !std::isfinite(q.w)) {
    std::snprintf(text, sizeof text, "non-finite quaternion (x %g, y %g, z %g, w %g)", q.x, q.y,
                  q.z, q.w);
    return text;
  }
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (std::abs(norm - 1.0) > kUnitTolerance) {
    std::snprintf(text, sizeof text,
                  "quaternion of norm %.6g, not a rotation (|norm - 1| must be <= %g)", norm,
                  kUnitTolerance);
    return text;
  }
  return {};
}

InitialPose to_initial_pose(const Sample& s) {
  InitialPose pose;
  pose.stamp_ns = detail::from_ros_time(s.header.stamp).ns;
  pose.frame_id = detail::to_string(s.header.frame_id);
  const auto& p = s.pose.pose.position;
  const auto& q = s.pose.pose.orientation;
  pose.T_frame_base = Eigen::Isometry3d::Identity();
  pose.T_frame_base.linear() = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().matrix();
  pose.T_frame_base.translation() = Eigen::Vector3d(p.x, p.y, p.z);
  std::copy(std::begin(s.pose.covariance), std::end(s.pose.covariance), pose.covariance.begin());
  return pose;
}

}  // namespace

std::unique_ptr<InitialPoseReader> InitialPoseReader::create(const DdsConfig& config,
                                                             std::string& error) {
  if (config.initial_pose_topic.empty()) return nullptr;
  std::shared_ptr<detail::Participant> participant = detail::Participant::open(config, error);
  if (!participant) return nullptr;
  std::unique_ptr<InitialPoseReader> reader(
      new InitialPoseReader(std::move(participant), config.initial_pose_topic));
  if (!reader->open(error)) return nullptr;
  return reader;
}

std::unique_ptr<InitialPoseReader> InitialPoseReader::create(const Publisher& publisher,
                                                             const DdsConfig& config,
                                                             std::string& error) {
  if (config.initial_pose_topic.empty()) return nullptr;
  std::unique_ptr<InitialPoseReader> reader(
      new InitialPoseReader(publisher.participant(), config.initial_pose_topic));
  if (!reader->open(error)) return nullptr;
  return reader;
}

InitialPoseReader::InitialPoseReader(std::shared_ptr<detail::Participant> participant,
                                     std::string topic)
    : participant_(std::move(participant)), topic_(std::move(topic)) {}

bool InitialPoseReader::open(std::string& error) {
  const dds_entity_t participant = participant_->handle();
  topic_entity_ = detail::create_initial_pose_topic(participant, topic_, error);
  if (topic_entity_ < 0) return false;
  dds_qos_t* qos = detail::make_initial_pose_qos();
  reader_ = dds_create_reader(participant, topic_entity_, qos, nullptr);
  dds_delete_qos(qos);
  if (reader_ < 0) {
    // Under DDS Security this is "Not Allowed By Security" unless the permissions let posed
    // subscribe to the topic.
    error = detail::describe_error(topic_ + ": create reader", reader_);
    return false;
  }
  return true;
}

InitialPoseReader::~InitialPoseReader() {
  // The participant may be the Publisher's and outlive this reader: delete what is ours.
  if (reader_ > 0) dds_delete(reader_);
  if (topic_entity_ > 0) dds_delete(topic_entity_);
}

std::optional<InitialPose> InitialPoseReader::take_newest() {
  // The reader's history holds at most 5 (its QoS), so one batch takes everything waiting.
  constexpr std::size_t kBatch = 8;
  std::optional<InitialPose> newest;
  std::uint64_t good = 0;
  for (;;) {
    std::array<void*, kBatch> samples{};  // null: Cyclone lends its own buffers
    std::array<dds_sample_info_t, kBatch> infos{};
    const dds_return_t n = dds_take(reader_, samples.data(), infos.data(), kBatch, kBatch);
    if (n <= 0) break;
    // Oldest first (one keyless instance, reception order), so the last good one is the newest.
    for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
      if (!infos[i].valid_data) continue;  // dispose/unregister notices carry no sample
      const auto& sample = *static_cast<const Sample*>(samples[i]);
      if (const std::string fault = fault_of(sample); !fault.empty()) {
        refused_.fetch_add(1, std::memory_order_relaxed);
        log_refused(fault, drivers::host_now());
        continue;
      }
      newest = to_initial_pose(sample);
      ++good;
    }
    dds_return_loan(reader_, samples.data(), n);
    if (static_cast<std::size_t>(n) < kBatch) break;
  }
  if (good > 1) dropped_.fetch_add(good - 1, std::memory_order_relaxed);
  return newest;
}

void InitialPoseReader::log_refused(const std::string& why, HostTime now) {
  if (last_log_ && now - *last_log_ < kLogInterval) {
    ++unlogged_refusals_;
    return;
  }
  if (unlogged_refusals_ > 0) {
    POSED_LOG_WARN("%s: refused an initial pose: %s (and %llu more since the last such line)",
                   topic_.c_str(), why.c_str(),
                   static_cast<unsigned long long>(unlogged_refusals_));
  } else {
    POSED_LOG_WARN("%s: refused an initial pose: %s", topic_.c_str(), why.c_str());
  }
  last_log_ = now;
  unlogged_refusals_ = 0;
}

std::uint32_t InitialPoseReader::matched_publishers() const {
  dds_subscription_matched_status_t status{};
  if (dds_get_subscription_matched_status(reader_, &status) != DDS_RETCODE_OK) return 0;
  return status.current_count;
}

}  // namespace posed::dds
