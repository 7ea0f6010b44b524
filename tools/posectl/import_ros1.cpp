// posectl import for ROS 1 bags (docs/import.md). Every connection of the bag becomes an MCAP
// channel on its original topic, as `mcap convert` writes ROS 1 data: message_encoding ros1, a
// ros1msg schema (name = the ROS type, data = the connection's message_definition), metadata
// callerid / latching / md5sum; log time = the bag's receive time, publish time = the message's
// header.stamp when its type starts with a std_msgs/Header (else the receive time).
//
// A topic in the topic map also gets posed.stream, posed.wire_format = "ros1:<type>" and
// posed.source_channel = 0, which is what makes `posed --replay` feed it to that stream.

#include <cstdio>
#include <map>
#include <set>
#include <utility>

#include "drivers/common/wire_format.hpp"
#include "drivers/recording/mcap_writer.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "drivers/recording/ros1_bag_reader.hpp"
#include "drivers/recording/ros1_messages.hpp"
#include "tools/posectl/import.hpp"

namespace posed::posectl::import {

namespace rec = drivers::recording;
namespace raw = rec::raw;
namespace ros1 = rec::ros1;

namespace {

std::span<const std::byte> as_bytes(const std::string& s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

/// Output channels, created as the bag's connections are first met.
class ChannelTable {
 public:
  ChannelTable(rec::McapWriter& writer, const ImportOptions& options, ImportResult& result)
      : writer_(writer), options_(options), result_(result) {}

  struct Out {
    std::uint16_t id = 0;
    std::size_t summary = 0;
    std::uint32_t sequence = 0;
    bool header_first = false;  ///< the type starts with a std_msgs/Header
  };

  Out& channel_for(const ros1::BagConnection& c) {
    if (const auto it = by_connection_.find(c.id); it != by_connection_.end()) return it->second;
    Out out;
    const auto schema_key = std::make_pair(c.type, c.message_definition);
    auto schema = schemas_.find(schema_key);
    if (schema == schemas_.end()) {
      const std::uint16_t id =
          writer_.add_schema(c.type, raw::kRos1SchemaEncoding, as_bytes(c.message_definition));
      schema = schemas_.emplace(schema_key, id).first;
    }
    std::map<std::string, std::string> metadata{{"md5sum", c.md5sum},
                                                {"latching", c.latching ? "true" : "false"}};
    if (!c.callerid.empty()) metadata["callerid"] = c.callerid;
    const std::string stream = stream_for(c);
    if (!stream.empty()) {
      metadata[std::string(raw::kStreamKey)] = stream;
      metadata[std::string(raw::kWireFormatKey)] = std::string(drivers::wire::kRos1Prefix) + c.type;
      metadata[std::string(raw::kSourceChannelKey)] = "0";
    }
    out.id = writer_.add_channel(c.topic, raw::kRos1MessageEncoding, schema->second, metadata);
    out.header_first = ros1::definition_starts_with_header(c.message_definition);
    out.summary = result_.channels.size();
    result_.channels.push_back({c.topic, c.type, stream, 0, 0});
    return by_connection_.emplace(c.id, out).first->second;
  }

 private:
  /// The stream a connection feeds, or "" (unmapped, or the stream is taken by another topic).
  std::string stream_for(const ros1::BagConnection& c) {
    const auto it = options_.topic_map.find(c.topic);
    if (it == options_.topic_map.end() || it->second.empty()) return "";
    const auto [owner, inserted] = stream_owner_.emplace(it->second, c.topic);
    if (!inserted && owner->second != c.topic) {
      result_.warnings.push_back("topic " + c.topic + " maps to stream '" + it->second +
                                 "', which " + owner->second +
                                 " already feeds: kept as a plain ros1 channel");
      return "";
    }
    return it->second;
  }

  rec::McapWriter& writer_;
  const ImportOptions& options_;
  ImportResult& result_;
  std::map<std::uint32_t, Out> by_connection_;
  std::map<std::pair<std::string, std::string>, std::uint16_t> schemas_;
  std::map<std::string, std::string> stream_owner_;
};

}  // namespace

int import_ros1_bag(const ImportOptions& options, ImportResult& result) {
  result.kind = "ROS 1 bag";
  Progress progress("bag " + options.in_path);
  std::uint64_t messages_written = 0;
  ros1::BagReaderOptions reader_options;
  reader_options.progress = [&](std::uint64_t done, std::uint64_t total) {
    progress.update(done, total, messages_written);
  };
  ros1::BagReader reader;
  std::string error;
  if (!reader.open(options.in_path, error, reader_options)) {
    std::fprintf(stderr, "posectl import: %s\n", error.c_str());
    return 1;
  }
  result.input_bytes = reader.file_size_bytes();
  rec::McapWriterOptions writer_options = options.writer;
  writer_options.profile = "ros1";
  rec::McapWriter writer;
  if (!writer.open(options.out_path, writer_options, error)) {
    std::fprintf(stderr, "posectl import: %s\n", error.c_str());
    return 1;
  }
  ChannelTable table(writer, options, result);
  ros1::BagMessage m;
  while (reader.next(m)) {
    ChannelTable::Out& out = table.channel_for(*m.connection);
    std::uint64_t publish_ns = m.receive_time_ns;
    ros1::Header header;
    if (out.header_first && ros1::decode_header(m.data, header) == ros1::Ros1Status::kOk &&
        header.stamp_ns > 0) {
      publish_ns = static_cast<std::uint64_t>(header.stamp_ns);
    }
    if (!writer.write_message(out.id, out.sequence++, m.receive_time_ns, publish_ns, m.data)) {
      std::fprintf(stderr, "posectl import: %s\n", writer.error().c_str());
      return 1;
    }
    ChannelSummary& cs = result.channels[out.summary];
    ++cs.messages;
    cs.bytes += m.data.size();
    if (result.messages++ == 0) result.first_log_ns = m.receive_time_ns;
    result.last_log_ns = std::max(result.last_log_ns, m.receive_time_ns);
    messages_written = result.messages;
  }
  // Connections without a message still become channels: the bag had them.
  for (const auto& [id, c] : reader.connections()) table.channel_for(c);

  if (!reader.indexed()) {
    result.notes.push_back("the bag's index was missing or unusable: read sequentially");
  }
  for (const ros1::BagIssue& i : reader.issues()) {
    result.warnings.push_back("offset " + std::to_string(i.offset) + ": " + i.what);
  }
  if (reader.counters().issues > reader.issues().size()) {
    result.warnings.push_back(std::to_string(reader.counters().issues - reader.issues().size()) +
                              " more problems not listed");
  }
  if (!reader.stop_reason().empty()) {
    result.warnings.push_back("reading stopped early: " + reader.stop_reason());
  }
  writer.write_metadata(raw::kMetadataName,
                        recording_metadata(options, "ROS time of the bag (receive time) [ns]"));
  if (!writer.close()) {
    std::fprintf(stderr, "posectl import: %s\n", writer.error().c_str());
    return 1;
  }
  return 0;
}

}  // namespace posed::posectl::import
