#include "daemon/pipeline/replay_sources.hpp"

#include <charconv>
#include <set>

#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/mcap_replay_source.hpp"
#include "drivers/recording/raw_channels.hpp"

namespace posed::pipeline {

namespace recording = drivers::recording;

ReplaySources make_replay_sources(const ReplayOptions& options, std::string& error) {
  ReplaySources out;
  recording::McapReader reader;
  if (!reader.open(options.path, error)) return out;
  // Channels and metadata come from the summary; a file cut short has none, so scan it.
  if (reader.channels().empty() || reader.metadata().empty()) {
    recording::McapMessage message;
    while (reader.next(message)) {
    }
  }
  std::set<std::string> streams;
  for (const auto& [id, channel] : reader.channels()) {
    if (channel.message_encoding != recording::raw::kMessageEncoding) continue;
    const auto it = channel.metadata.find(std::string(recording::raw::kStreamKey));
    if (it != channel.metadata.end()) streams.insert(it->second);
  }
  for (const auto& record : reader.metadata()) {
    if (record.name != recording::raw::kMetadataName) continue;
    const auto it = record.entries.find(std::string(recording::raw::kHostToWallKey));
    std::int64_t ns = 0;
    if (it != record.entries.end() &&
        std::from_chars(it->second.data(), it->second.data() + it->second.size(), ns).ec ==
            std::errc{}) {
      out.host_to_wall = HostToWall{Duration::from_ns(ns)};
      out.have_host_to_wall = true;
    }
  }
  if (!streams.count("imu")) {
    error = options.path + ": no raw IMU stream (/posed/raw/imu) to replay; found: " +
            (streams.empty() ? std::string("no raw streams") : *streams.begin());
    return out;
  }

  const auto make = [&](const std::string& stream) {
    recording::McapReplayConfig c;
    c.path = options.path;
    c.stream = stream;
    c.name = stream;
    c.rate = options.rate;
    c.start_offset = Duration::from_seconds(options.start_s);
    c.duration = Duration::from_seconds(options.duration_s);
    c.loop = options.loop;
    return std::make_unique<recording::McapReplaySource>(std::move(c));
  };
  out.built.sources.imu = make("imu");
  if (streams.count("lidar")) out.built.sources.lidar = make("lidar");
  // Cameras replay when recorded; a recording of other streams (a depth camera, a second IMU)
  // is listed but has no stage to go to.
  if (streams.count("visible")) out.built.sources.visible = make("visible");
  if (streams.count("thermal")) out.built.sources.thermal = make("thermal");
  for (const auto& s : streams) out.streams += (out.streams.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace posed::pipeline
