#include "daemon/pipeline/replay_sources.hpp"

#include <charconv>
#include <set>

#include "drivers/common/log.hpp"
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
    if (!recording::raw::is_stream_channel(channel.message_encoding, channel.metadata)) continue;
    const auto it = channel.metadata.find(std::string(recording::raw::kStreamKey));
    if (it == channel.metadata.end()) continue;
    streams.insert(it->second);
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
    std::string found;
    for (const auto& s : streams) found += (found.empty() ? "" : ", ") + s;
    error = options.path +
            ": no IMU stream to replay (/posed/raw/imu, or an imported topic mapped to imu: "
            "posectl import --topic-map TOPIC=imu); found: " +
            (found.empty() ? std::string("no streams") : found);
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
  // Cameras replay as raw frames or as imported sensor_msgs/Image (camera_stage_ros1.cpp).
  // Other streams (the D435i's depth, a second IMU) have no stage: listed, said once in the log,
  // never read.
  const auto replay_camera = [&](const std::string& stream) { return streams.count(stream) != 0; };
  if (replay_camera("visible")) out.built.sources.visible = make("visible");
  if (replay_camera("thermal")) out.built.sources.thermal = make("thermal");
  std::string skipped;
  for (const auto& s : streams) {
    const bool replayed = s == "imu" || s == "lidar" || s == "visible" || s == "thermal";
    out.streams += (out.streams.empty() ? "" : ", ") + s + (replayed ? "" : " (not replayed)");
    if (!replayed) skipped += (skipped.empty() ? "" : ", ") + s;
  }
  if (!skipped.empty()) {
    POSED_LOG_NOTICE("%s: no pipeline stage for stream(s) %s: not replayed", options.path.c_str(),
                     skipped.c_str());
  }
  return out;
}

}  // namespace posed::pipeline
