#pragma once
// Where the DDS messages go besides DDS (dds::MessageTap): into the recording as ros2msg
// channels next to the raw ones (posed --record, --record-outputs), so a recording opens in
// Foxglove with the tf tree, path, diagnostics and clouds as the robot published them; and to
// the Foxglove WebSocket server, one channel per topic, for Foxglove Studio live. Nothing is
// serialised for a destination nobody listens to: wants() asks the server whether a client
// subscribes now.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "daemon/dds/message_tap.hpp"

namespace posed {

namespace drivers::recording {
class Recorder;
}
namespace foxglove {
class Server;
}

/// Parses --record-outputs: comma-separated topic short names (tf, tf_static, path,
/// diagnostics, status, cloud, map, image), "all" or "none". false with `error` naming the bad
/// item. The default (RunOptions::record_outputs) leaves out the clouds and images: a scan is
/// ~1.2 MB, three times the raw packets it came from.
bool parse_record_outputs(const std::string& text, std::vector<dds::Topic>& topics,
                          std::string& error);

class OutputTap final : public dds::MessageTap {
 public:
  /// Records `record_topics` into `recorder` (null: nothing recorded). rt/posed/odom and pose
  /// are recorded by PoseSinks whatever DDS does, so they are not accepted here. Serves
  /// `served_topics` on `foxglove` (null: no server), advertising a channel for each now.
  OutputTap(drivers::recording::Recorder* recorder, std::span<const dds::Topic> record_topics,
            foxglove::Server* foxglove = nullptr, std::span<const dds::Topic> served_topics = {});

  bool wants(dds::Topic topic) const override;
  void deliver(dds::Topic topic, WallTime stamp, std::span<const std::byte> cdr) override;

  /// Messages the recording refused (queue full) [count], per topic.
  std::uint64_t record_drops(dds::Topic topic) const {
    return record_drops_[static_cast<std::size_t>(topic)];
  }

 private:
  static constexpr std::uint16_t kNone = 0xFFFF;
  drivers::recording::Recorder* recorder_;
  /// recording channel per Topic; kNone: not recorded
  std::array<std::uint16_t, dds::kAllTopics.size()> record_channel_;
  std::array<std::uint64_t, dds::kAllTopics.size()> record_drops_{};
  foxglove::Server* foxglove_;
  /// Foxglove channel per Topic; 0: not served
  std::array<std::uint32_t, dds::kAllTopics.size()> foxglove_channel_{};
};

}  // namespace posed
