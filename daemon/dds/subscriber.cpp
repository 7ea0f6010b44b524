#include "daemon/dds/subscriber.hpp"

#include <array>

#include "daemon/dds/convert.hpp"
#include "daemon/dds/participant.hpp"
#include "drivers/common/host_clock.hpp"

namespace posed::dds {

struct Subscriber::Impl {
  std::unique_ptr<detail::Participant> participant;
  /// reader per Topic (index = enum value); 0 when not subscribed
  std::array<dds_entity_t, kAllTopics.size()> readers{};
  dds_entity_t waitset = 0;

  dds_entity_t reader(Topic topic) const { return readers[static_cast<std::size_t>(topic)]; }

  /// Takes loaned samples in batches and appends them converted; `fill` sets the strings.
  template <class CSample, class Message, class Fill>
  std::size_t take(Topic topic, std::vector<Received<Message>>& out, Fill fill) {
    const dds_entity_t r = reader(topic);
    if (r == 0) return 0;
    constexpr std::size_t kBatch = 32;
    std::size_t taken = 0;
    for (;;) {
      std::array<void*, kBatch> samples{};  // null: Cyclone lends its own buffers
      std::array<dds_sample_info_t, kBatch> infos{};
      const dds_return_t n = dds_take(r, samples.data(), infos.data(), kBatch, kBatch);
      if (n <= 0) return taken;
      const WallTime wall = drivers::wall_now();
      const HostTime host = drivers::host_now();
      for (dds_return_t i = 0; i < n; ++i) {
        const auto idx = static_cast<std::size_t>(i);
        if (!infos[idx].valid_data) continue;  // dispose/unregister notices carry no sample
        const auto& sample = *static_cast<const CSample*>(samples[idx]);
        Received<Message> received{detail::to_plain(sample), {}, {}, wall, host};
        fill(sample, received);
        out.push_back(std::move(received));
        ++taken;
      }
      dds_return_loan(r, samples.data(), n);
      if (static_cast<std::size_t>(n) < kBatch) return taken;
    }
  }
};

std::unique_ptr<Subscriber> Subscriber::create(const DdsConfig& config,
                                               std::span<const Topic> topics, std::string& error) {
  static constexpr std::array kPosed = {Topic::kOdom, Topic::kPose, Topic::kStatus};
  if (topics.empty()) topics = kPosed;
  auto impl = std::make_unique<Impl>();
  impl->participant = detail::Participant::open(config, error);
  if (!impl->participant) return nullptr;
  const dds_entity_t participant = impl->participant->handle();
  impl->waitset = dds_create_waitset(participant);
  if (impl->waitset < 0) {
    error = detail::describe_error("DDS waitset", impl->waitset);
    return nullptr;
  }
  bool ok = true;
  for (Topic topic : topics) {
    dds_entity_t& reader = impl->readers[static_cast<std::size_t>(topic)];
    if (reader != 0) continue;  // listed twice
    const std::string name(topic_name(topic));
    const dds_entity_t t = detail::create_topic(participant, topic, error);
    if (t < 0) {
      ok = false;
      break;
    }
    dds_qos_t* qos = detail::make_topic_qos(topic);
    reader = dds_create_reader(participant, t, qos, nullptr);
    dds_delete_qos(qos);
    if (reader < 0) {
      error = detail::describe_error(name + ": create reader", reader);
      ok = false;
      break;
    }
    const dds_entity_t condition = dds_create_readcondition(reader, DDS_ANY_STATE);
    const dds_return_t rc =
        condition < 0 ? condition : dds_waitset_attach(impl->waitset, condition, reader);
    if (rc < 0) {
      error = detail::describe_error(name + ": attach read condition", rc);
      ok = false;
      break;
    }
  }
  if (!ok) return nullptr;  // ~Participant deletes whatever was created
  return std::unique_ptr<Subscriber>(new Subscriber(std::move(impl)));
}

Subscriber::Subscriber(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Subscriber::~Subscriber() = default;

bool Subscriber::wait(Duration timeout) {
  const dds_return_t n = dds_waitset_wait(impl_->waitset, nullptr, 0, timeout.ns);
  return n > 0;
}

std::size_t Subscriber::take_odom(std::vector<Received<OdomMessage>>& out) {
  return impl_->take<nav_msgs_msg_dds__Odometry_>(
      Topic::kOdom, out, [](const nav_msgs_msg_dds__Odometry_& s, Received<OdomMessage>& r) {
        r.frame_id = detail::to_string(s.header.frame_id);
        r.child_frame_id = detail::to_string(s.child_frame_id);
      });
}

std::size_t Subscriber::take_pose(std::vector<Received<PoseMessage>>& out) {
  return impl_->take<geometry_msgs_msg_dds__PoseStamped_>(
      Topic::kPose, out,
      [](const geometry_msgs_msg_dds__PoseStamped_& s, Received<PoseMessage>& r) {
        r.frame_id = detail::to_string(s.header.frame_id);
      });
}

std::size_t Subscriber::take_status(std::vector<Received<StatusMessage>>& out) {
  return impl_->take<posed_msgs_msg_dds__Status_>(
      Topic::kStatus, out, [](const posed_msgs_msg_dds__Status_& s, Received<StatusMessage>& r) {
        r.frame_id = detail::to_string(s.header.frame_id);
      });
}

std::size_t Subscriber::take_tf(Topic topic, std::vector<Received<TfMessage>>& out) {
  if (topic != Topic::kTf && topic != Topic::kTfStatic) return 0;
  return impl_->take<tf2_msgs_msg_dds__TFMessage_>(
      topic, out, [](const tf2_msgs_msg_dds__TFMessage_&, Received<TfMessage>&) {});
}

std::size_t Subscriber::take_path(std::vector<Received<PathMessage>>& out) {
  return impl_->take<nav_msgs_msg_dds__Path_>(
      Topic::kPath, out, [](const nav_msgs_msg_dds__Path_& s, Received<PathMessage>& r) {
        r.frame_id = detail::to_string(s.header.frame_id);
      });
}

std::size_t Subscriber::take_diagnostics(std::vector<Received<DiagnosticsMessage>>& out) {
  return impl_->take<diagnostic_msgs_msg_dds__DiagnosticArray_>(
      Topic::kDiagnostics, out,
      [](const diagnostic_msgs_msg_dds__DiagnosticArray_& s, Received<DiagnosticsMessage>& r) {
        r.frame_id = detail::to_string(s.header.frame_id);
      });
}

std::size_t Subscriber::take_cloud(Topic topic, std::vector<Received<CloudMessage>>& out) {
  if (topic != Topic::kCloud && topic != Topic::kMap) return 0;
  return impl_->take<sensor_msgs_msg_dds__PointCloud2_>(
      topic, out, [](const sensor_msgs_msg_dds__PointCloud2_& s, Received<CloudMessage>& r) {
        r.frame_id = detail::to_string(s.header.frame_id);
      });
}

std::size_t Subscriber::take_image(std::vector<Received<ImageMessage>>& out) {
  return impl_->take<sensor_msgs_msg_dds__CompressedImage_>(
      Topic::kImage, out,
      [](const sensor_msgs_msg_dds__CompressedImage_& s, Received<ImageMessage>& r) {
        r.frame_id = detail::to_string(s.header.frame_id);
      });
}

std::uint32_t Subscriber::matched_publishers(Topic topic) const {
  const dds_entity_t reader = impl_->reader(topic);
  if (reader == 0) return 0;
  dds_subscription_matched_status_t status{};
  if (dds_get_subscription_matched_status(reader, &status) != DDS_RETCODE_OK) return 0;
  return status.current_count;
}

}  // namespace posed::dds
