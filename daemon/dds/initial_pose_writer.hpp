#pragma once
// The sending end of rt/initialpose, as RViz's "2D Pose Estimate" tool is: for
// `posectl initialpose` and the tests. The daemon only reads it (initial_pose_reader.hpp).

#include <cstdint>
#include <memory>
#include <string>

#include "core/time.hpp"
#include "daemon/dds/initial_pose_reader.hpp"
#include "daemon/dds/messages.hpp"

namespace posed::dds {

/// One participant with a writer on DdsConfig::initial_pose_topic, RViz's QoS. One thread.
class InitialPoseWriter {
 public:
  /// nullptr with `error` set on failure (also when config.initial_pose_topic is empty).
  static std::unique_ptr<InitialPoseWriter> create(const DdsConfig& config, std::string& error);
  ~InitialPoseWriter();
  InitialPoseWriter(const InitialPoseWriter&) = delete;
  InitialPoseWriter& operator=(const InitialPoseWriter&) = delete;

  /// Blocks until a reader matched (true) or `timeout` passed (false). Volatile durability: a
  /// pose written before a reader matched never reaches it.
  bool wait_for_reader(Duration timeout);
  /// Readers currently matched [count].
  std::uint32_t matched_subscribers() const;
  /// Writes `pose` (its rotation as a unit quaternion); false with `error` set when Cyclone
  /// rejected it.
  bool publish(const InitialPose& pose, std::string& error);
  /// Blocks until every matched reader acknowledged what was written (true) or `timeout`
  /// passed: a process that exits right after publish would otherwise take the sample with it.
  bool wait_acknowledged(Duration timeout);

 private:
  InitialPoseWriter() = default;

  std::unique_ptr<detail::Participant> participant_;
  std::string topic_;
  std::int32_t writer_ = 0;  // dds_entity_t, without dds.h in this header
  std::int32_t waitset_ = 0;
};

}  // namespace posed::dds
