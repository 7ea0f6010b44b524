#include "daemon/pipeline/replay_sources.hpp"

#include <charconv>
#include <set>

#include "drivers/common/log.hpp"
#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/mcap_replay_source.hpp"
#include "drivers/recording/raw_channels.hpp"

namespace posed::pipeline {

namespace recording = drivers::recording;
namespace raw = drivers::recording::raw;

namespace {

/// How far a paced replay reads ahead of what it delivered: longer than any stall of a reader
/// at normal priority behind the real-time stages (a scan's 6-8 ms), short enough that the
/// frames held stay a few MB (4 visible frames at 25 Hz).
constexpr Duration kPacedReadAhead = Duration::from_ns(150'000'000);

/// Opens a recording with its channels and metadata known: they come from the summary, and a
/// file cut short has none, so it is scanned to the damage.
bool open_with_channels(const std::string& path, recording::McapReader& reader,
                        std::string& error) {
  if (!reader.open(path, error)) return false;
  if (reader.channels().empty() || reader.metadata().empty()) {
    recording::McapMessage message;
    while (reader.next(message)) {
    }
  }
  return true;
}

/// The recorded streams as a list for messages: "imu, lidar", or "no streams".
std::string listed(const std::set<std::string>& streams) {
  std::string out;
  for (const auto& s : streams) out += (out.empty() ? "" : ", ") + s;
  return out.empty() ? "no streams" : out;
}

}  // namespace

bool read_recorded_config(const std::string& path, std::string& yaml, std::string& error) {
  recording::McapReader reader;
  if (!open_with_channels(path, reader, error)) return false;
  yaml.clear();
  for (const auto& [id, channel] : reader.channels()) {
    const std::string config = raw::metadata_value(channel.metadata, raw::kConfigKey);
    if (config.empty()) continue;
    // Every raw channel carries the same text; the IMU's, which every replay needs, is preferred.
    if (yaml.empty() || raw::metadata_value(channel.metadata, raw::kStreamKey) == "imu")
      yaml = config;
  }
  if (yaml.empty()) {
    error = path +
            ": no recorded configuration (channel metadata posed.config): only posed --record and "
            "posectl record write one, not posectl import or posectl sim; give --config instead";
    return false;
  }
  return true;
}

ReplaySources make_replay_sources(const ReplayOptions& options, std::string& error) {
  ReplaySources out;
  recording::McapReader reader;
  if (!open_with_channels(options.path, reader, error)) return out;
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
  // --streams: the ones asked for, each of them recorded; the rest stay listed, not replayed.
  std::set<std::string> left_out;
  if (!options.only_streams.empty()) {
    const std::set<std::string> wanted(options.only_streams.begin(), options.only_streams.end());
    for (const std::string& s : wanted) {
      if (streams.count(s)) continue;
      error = options.path + ": --streams names " + s + ", which the recording does not have (" +
              listed(streams) + ")";
      return out;
    }
    if (!wanted.count("imu")) {
      error = "--streams must include imu: every estimate starts from the IMU";
      return out;
    }
    for (const std::string& s : streams) {
      if (!wanted.count(s)) left_out.insert(s);
    }
    for (const std::string& s : left_out) streams.erase(s);
  }
  if (!streams.count("imu")) {
    error = options.path +
            ": no IMU stream to replay (/posed/raw/imu, or an imported topic mapped to imu: "
            "posectl import --topic-map TOPIC=imu); found: " +
            listed(streams);
    return out;
  }

  const auto timeline =
      options.live_stamps ? std::make_shared<recording::ReplayTimeline>() : nullptr;
  // The streams read the file side by side; each chunk is decompressed once for all of them.
  out.chunks = std::make_shared<recording::McapChunkCache>();
  const auto& chunks = out.chunks;
  const auto make = [&](const std::string& stream) {
    recording::McapReplayConfig c;
    c.path = options.path;
    c.stream = stream;
    c.name = stream;
    c.rate = options.rate;
    c.start_offset = Duration::from_seconds(options.start_s);
    c.duration = Duration::from_seconds(options.duration_s);
    // One pass: run_daemon runs the next through a pipeline of its own (options.loop).
    c.loop = false;
    c.time_shift = options.time_shift;
    c.live_timeline = timeline;
    c.chunk_cache = chunks;
    // Paced replays read the file on threads of their own, so a stage waits only for the
    // message to be due, as it would for its device (mcap_replay_source.hpp). At --max-speed
    // the stages are the pace and read for themselves: no extra threads, no copies.
    if (c.rate > 0 || timeline) c.read_ahead = kPacedReadAhead;
    auto source = std::make_unique<recording::McapReplaySource>(std::move(c));
    out.replayers.push_back(source.get());
    return source;
  };
  out.built.sources.imu = make("imu");
  out.built.sources.paced = options.rate > 0;
  out.built.sources.live_stamps = options.live_stamps;
  if (streams.count("lidar")) {
    out.built.sources.lidar = make("lidar");
    if (options.recorded_config) {
      // The calibration file's text as it was when recorded (empty: the built-in table was used).
      for (const auto& [id, channel] : reader.channels()) {
        if (raw::metadata_value(channel.metadata, raw::kStreamKey) != "lidar") continue;
        const std::string text =
            raw::metadata_value(channel.metadata, raw::kLidarCalibrationTextKey);
        if (text.empty()) continue;
        out.built.sources.lidar_calibration_text = text;
        out.built.sources.lidar_calibration_name =
            options.path + " (recorded " +
            raw::metadata_value(channel.metadata, raw::kLidarCalibrationKey) + ")";
        break;
      }
    }
  }
  // Cameras replay as raw frames or as imported sensor_msgs/Image (camera_stage_ros1.cpp); the
  // D435i's depth node too when features take its depth (depth_camera.feature_depth). Other
  // streams have no stage: listed, said once in the log, never read.
  const auto replay_camera = [&](const std::string& stream) { return streams.count(stream) != 0; };
  if (replay_camera("visible")) out.built.sources.visible = make("visible");
  if (replay_camera("thermal")) out.built.sources.thermal = make("thermal");
  if (replay_camera("depth") && options.depth) out.built.sources.depth = make("depth");
  // The D435i's IMU as raw IIO records (posed --record, posectl sim --realsense-imu): the A9's
  // backup. An imported sensor_msgs/Imu of it has no stage yet.
  bool rsimu_raw = false;
  for (const auto& [id, channel] : reader.channels()) {
    if (raw::metadata_value(channel.metadata, raw::kStreamKey) == "realsense_imu" &&
        channel.message_encoding == raw::kMessageEncoding) {
      rsimu_raw = true;
    }
  }
  if (rsimu_raw) out.built.sources.realsense_imu = make("realsense_imu");
  std::string skipped;
  for (const auto& s : left_out)
    out.streams += (out.streams.empty() ? "" : ", ") + s + " (left out by --streams)";
  for (const auto& s : streams) {
    const bool replayed = s == "imu" || s == "lidar" || s == "visible" || s == "thermal" ||
                          (s == "depth" && out.built.sources.depth) ||
                          (s == "realsense_imu" && out.built.sources.realsense_imu);
    out.streams += (out.streams.empty() ? "" : ", ") + s + (replayed ? "" : " (not replayed)");
    if (!replayed) {
      skipped += (skipped.empty() ? "" : ", ") + s;
      if (s == "depth") skipped += " (depth_camera.feature_depth is false)";
    }
  }
  if (!skipped.empty()) {
    POSED_LOG_NOTICE("%s: no pipeline stage for stream(s) %s: not replayed", options.path.c_str(),
                     skipped.c_str());
  }
  return out;
}

}  // namespace posed::pipeline
