#include "daemon/output_tap.hpp"

#include <sstream>

#include "daemon/foxglove/server.hpp"
#include "drivers/recording/recorder.hpp"
#include "drivers/recording/ros2_schemas.hpp"

namespace posed {

bool parse_record_outputs(const std::string& text, std::vector<dds::Topic>& topics,
                          std::string& error) {
  topics.clear();
  if (text == "none" || text.empty()) return true;
  if (text == "all") {
    for (dds::Topic t : dds::kAllTopics) {
      if (t != dds::Topic::kOdom && t != dds::Topic::kPose) topics.push_back(t);
    }
    return true;
  }
  std::stringstream items(text);
  std::string item;
  while (std::getline(items, item, ',')) {
    dds::Topic t{};
    if (!dds::parse_topic(item, t) || t == dds::Topic::kOdom || t == dds::Topic::kPose) {
      error = "--record-outputs: '" + item +
              "' is not one of tf, tf_static, path, diagnostics, status, cloud, map, image (or "
              "all, none); odom and pose are always recorded";
      return false;
    }
    topics.push_back(t);
  }
  return true;
}

OutputTap::OutputTap(drivers::recording::Recorder* recorder,
                     std::span<const dds::Topic> record_topics, foxglove::Server* foxglove,
                     std::span<const dds::Topic> served_topics)
    : recorder_(recorder), foxglove_(foxglove) {
  record_channel_.fill(kNone);
  if (foxglove_ != nullptr) {
    namespace ros2 = drivers::recording::ros2;
    for (dds::Topic t : served_topics) {
      const std::string_view type = dds::ros_type_name(t);
      // Transient-local on DDS, latched here: Studio connects whenever its user does.
      const bool latched = dds::transient_local(t);
      foxglove_channel_[static_cast<std::size_t>(t)] = foxglove_->add_channel(
          {std::string(dds::ros_topic_name(t)), std::string(ros2::kMessageEncoding),
           std::string(type), std::string(ros2::kSchemaEncoding),
           std::string(ros2::schema_for(type)), latched});
    }
  }
  if (recorder_ == nullptr) return;
  for (dds::Topic t : record_topics) {
    if (t == dds::Topic::kOdom || t == dds::Topic::kPose) continue;
    // ~1.2 MB a scan: 64 queued bound what a stalled disk costs to ~80 MB.
    record_channel_[static_cast<std::size_t>(t)] = recorder_->add_ros2_channel(
        dds::ros_topic_name(t), dds::ros_type_name(t), dds::large_messages(t) ? 64 : 0);
  }
}

bool OutputTap::wants(dds::Topic topic) const {
  const auto i = static_cast<std::size_t>(topic);
  return record_channel_[i] != kNone ||
         (foxglove_channel_[i] != 0 &&
          (dds::transient_local(topic) || foxglove_->has_subscribers(foxglove_channel_[i])));
}

void OutputTap::deliver(dds::Topic topic, WallTime stamp, std::span<const std::byte> cdr) {
  const auto i = static_cast<std::size_t>(topic);
  if (record_channel_[i] != kNone && !recorder_->write_ros2(record_channel_[i], stamp, cdr)) {
    ++record_drops_[i];
  }
  // Foxglove's log time is the message's stamp: its timeline then shows the data's time.
  if (foxglove_channel_[i] != 0) foxglove_->publish(foxglove_channel_[i], stamp.ns, cdr);
}

}  // namespace posed
