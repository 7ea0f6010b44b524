// posectl import for Sources that already speak posed's raw wire formats: a pcap/pcapng Velodyne
// capture (PcapSource: data and position ports) and a can-utils candump log
// (CandumpReplaySource: kernel CAN frames). Each is read as fast as it goes and every chunk is
// written as `posed --record` writes it (Recorder, raw_channels.hpp): topic /posed/raw/<stream>
// [/<n>], encoding posed-raw, log time = publish time = the chunk's host_receive (the capture's
// own time stamps), metadata posed.stream / posed.wire_format / posed.source_channel.

#include <cstdio>
#include <map>
#include <memory>

#include "drivers/common/source.hpp"
#include "drivers/imu/candump_log.hpp"
#include "drivers/recording/mcap_writer.hpp"
#include "drivers/recording/pcap_source.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "tools/posectl/import.hpp"

namespace posed::posectl::import {

namespace rec = drivers::recording;
namespace raw = rec::raw;

namespace {

/// Writes every chunk of `source` (already open) into `writer`'s raw channels for `stream`.
int copy_source(drivers::Source& source, const std::string& stream, rec::McapWriter& writer,
                const ImportOptions& options, ImportResult& result, Progress& progress) {
  std::map<std::uint32_t, std::uint16_t> channel_ids;  // source channel -> MCAP channel
  std::map<std::uint32_t, std::size_t> summary_index;
  std::map<std::uint32_t, std::uint32_t> sequence;
  drivers::RawChunk chunk;
  for (;;) {
    const drivers::ReadStatus rs = source.read(chunk, Duration::from_ms(100));
    if (rs == drivers::ReadStatus::kEndOfStream) break;
    if (rs != drivers::ReadStatus::kData) continue;
    auto it = channel_ids.find(chunk.channel);
    if (it == channel_ids.end()) {
      const std::string_view wire_format = source.wire_format(chunk.channel);
      if (wire_format.empty()) continue;  // a channel the Source never names: not recordable
      const std::map<std::string, std::string> metadata{
          {std::string(raw::kStreamKey), stream},
          {std::string(raw::kWireFormatKey), std::string(wire_format)},
          {std::string(raw::kSourceChannelKey), std::to_string(chunk.channel)},
          {"posed.import.source", options.in_path}};
      const std::string topic = raw::topic(stream, chunk.channel);
      const std::uint16_t id = writer.add_channel(topic, raw::kMessageEncoding, 0, metadata);
      it = channel_ids.emplace(chunk.channel, id).first;
      summary_index[chunk.channel] = result.channels.size();
      result.channels.push_back({topic, std::string(wire_format), stream, 0, 0});
    }
    const auto log_ns = static_cast<std::uint64_t>(chunk.host_receive.ns);
    if (!writer.write_message(it->second, sequence[chunk.channel]++, log_ns, log_ns, chunk.bytes)) {
      std::fprintf(stderr, "posectl import: %s\n", writer.error().c_str());
      return 1;
    }
    ChannelSummary& cs = result.channels[summary_index[chunk.channel]];
    ++cs.messages;
    cs.bytes += chunk.bytes.size();
    if (result.messages++ == 0) result.first_log_ns = log_ns;
    result.last_log_ns = std::max(result.last_log_ns, log_ns);
    if ((result.messages & 1023) == 0) progress.update(0, 0, result.messages);
  }
  return 0;
}

int finish(rec::McapWriter& writer, const ImportOptions& options, const std::string& clock) {
  writer.write_metadata(raw::kMetadataName, recording_metadata(options, clock));
  if (!writer.close()) {
    std::fprintf(stderr, "posectl import: %s\n", writer.error().c_str());
    return 1;
  }
  return 0;
}

}  // namespace

int import_pcap(const ImportOptions& options, ImportResult& result) {
  result.kind = "pcap capture";
  rec::PcapSourceConfig config;
  config.path = options.in_path;
  config.name = "lidar";
  config.ports = {options.data_port, options.position_port};
  config.speed = 0;  // as fast as we read
  rec::PcapSource source(config);
  std::string error;
  if (!source.open(error)) {
    std::fprintf(stderr, "posectl import: %s\n", error.c_str());
    return 1;
  }
  rec::McapWriter writer;
  if (!writer.open(options.out_path, options.writer, error)) {
    std::fprintf(stderr, "posectl import: %s\n", error.c_str());
    return 1;
  }
  Progress progress("pcap " + options.in_path);
  if (const int rc = copy_source(source, "lidar", writer, options, result, progress); rc != 0) {
    return rc;
  }
  const rec::PcapSourceStats stats = source.stats();
  if (stats.other_ports > 0) {
    result.notes.push_back(
        std::to_string(stats.other_ports) + " UDP datagrams to other ports than " +
        std::to_string(options.data_port) + "/" + std::to_string(options.position_port) +
        " left out (--data-port, "
        "--position-port)");
  }
  if (stats.not_udp > 0) {
    result.notes.push_back(std::to_string(stats.not_udp) + " frames that are not UDP left out");
  }
  if (stats.damaged > 0) {
    result.warnings.push_back(std::to_string(stats.damaged) +
                              " datagrams cut short by the capture (snaplen) left out");
  }
  if (!source.file_error().empty()) result.warnings.push_back(source.file_error());
  return finish(writer, options, "capture time (pcap time stamps, UNIX epoch) [ns]");
}

int import_candump(const ImportOptions& options, ImportResult& result) {
  result.kind = "candump log";
  drivers::can::CandumpReplaySource source(options.in_path, "imu");
  std::string error;
  if (!source.open(error)) {
    std::fprintf(stderr, "posectl import: %s\n", error.c_str());
    return 1;
  }
  rec::McapWriter writer;
  if (!writer.open(options.out_path, options.writer, error)) {
    std::fprintf(stderr, "posectl import: %s\n", error.c_str());
    return 1;
  }
  Progress progress("candump " + options.in_path);
  if (const int rc = copy_source(source, "imu", writer, options, result, progress); rc != 0) {
    return rc;
  }
  if (const auto rejected = source.counters().rejected; rejected > 0) {
    result.warnings.push_back(std::to_string(rejected) +
                              " malformed lines left out (the first ones are logged above with "
                              "their line numbers)");
  }
  return finish(writer, options, "candump time stamps (UNIX epoch) [ns]");
}

}  // namespace posed::posectl::import
