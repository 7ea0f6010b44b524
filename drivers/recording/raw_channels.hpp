#pragma once
// How posed stores the exact bytes a Source read in an MCAP file (DESIGN.md, Recordings). One
// MCAP channel per (stream, Source channel):
//
//   topic             /posed/raw/<stream>          Source channel 0 (e.g. the lidar data port)
//                     /posed/raw/<stream>/<n>      Source channel n > 0 (e.g. 1 = position port)
//   message_encoding  posed-raw                    the bytes exactly as read(); no schema (id 0)
//   log_time          RawChunk::host_receive       host CLOCK_MONOTONIC [ns]
//   publish_time      = log_time
//   metadata          posed.stream          the Source's name ("imu", "lidar")
//                     posed.wire_format     how to decode the bytes (kWire* below)
//                     posed.source_channel  the RawChunk::channel ("0", "1")
//                     + whatever the caller adds: sensor config, calibration text, device path
//
// Poses and ground truth are ROS 2 CDR messages on their own topics (ros2_messages.hpp), and a
// Metadata record named "posed" holds the host-to-wall clock offset of the recording.
//
// Imported ROS 1 bags (posectl import, docs/import.md) keep every connection as a channel on its
// own topic with message_encoding ros1 and a ros1msg schema; a channel whose topic maps onto a
// posed stream also carries posed.stream, posed.source_channel and posed.wire_format
// ("ros1:<type>", drivers/common/wire_format.hpp), and replays like a raw channel.

#include <charconv>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "drivers/common/wire_format.hpp"

namespace posed::drivers::recording::raw {

inline constexpr std::string_view kTopicPrefix = "/posed/raw/";
inline constexpr std::string_view kMessageEncoding = "posed-raw";

inline constexpr std::string_view kStreamKey = "posed.stream";
inline constexpr std::string_view kWireFormatKey = "posed.wire_format";
inline constexpr std::string_view kSourceChannelKey = "posed.source_channel";
/// what posed --record and posectl record add to every raw channel: the effective configuration
/// (print_config's YAML) and, on the lidar's, the calibration file's path and text
inline constexpr std::string_view kConfigKey = "posed.config";
inline constexpr std::string_view kLidarCalibrationKey = "posed.lidar.calibration";
inline constexpr std::string_view kLidarCalibrationTextKey = "posed.lidar.calibration_text";

/// A channel's metadata value for `key`; empty when the channel has none.
inline std::string metadata_value(const std::map<std::string, std::string>& metadata,
                                  std::string_view key) {
  const auto it = metadata.find(std::string(key));
  return it == metadata.end() ? std::string() : it->second;
}

// The wire formats (drivers/common/wire_format.hpp) under the names recordings use.
inline constexpr std::string_view kWireA9Serial = wire::kA9Serial;
inline constexpr std::string_view kWireVelodyneData = wire::kVelodyneData;
inline constexpr std::string_view kWireVelodynePosition = wire::kVelodynePosition;
inline constexpr std::string_view kWireCanFrame = wire::kCanFrame;

/// Imported ROS 1 messages (mcap.dev registry: message encoding "ros1", schema encoding
/// "ros1msg" holding the connection's message_definition).
inline constexpr std::string_view kRos1MessageEncoding = "ros1";
inline constexpr std::string_view kRos1SchemaEncoding = "ros1msg";

/// Whether a channel feeds a posed stream: raw Source bytes, or imported ROS 1 messages whose
/// topic was mapped onto a stream.
inline bool is_stream_channel(std::string_view message_encoding,
                              const std::map<std::string, std::string>& metadata) {
  if (message_encoding == kMessageEncoding) return true;
  return message_encoding == kRos1MessageEncoding &&
         metadata.find(std::string(kStreamKey)) != metadata.end();
}

/// The Metadata record with the recording's clock facts.
inline constexpr std::string_view kMetadataName = "posed";
/// key in that record: wall minus host monotonic time when the recording started [ns]
inline constexpr std::string_view kHostToWallKey = "host_to_wall_ns";

inline std::string topic(std::string_view stream, std::uint32_t source_channel) {
  std::string t(kTopicPrefix);
  t += stream;
  if (source_channel != 0) {
    t += '/';
    t += std::to_string(source_channel);
  }
  return t;
}

/// The Source channel number in a metadata value ("0" when absent or malformed).
inline std::uint32_t parse_source_channel(std::string_view text) {
  std::uint32_t v = 0;
  std::from_chars(text.data(), text.data() + text.size(), v);
  return v;
}

}  // namespace posed::drivers::recording::raw
