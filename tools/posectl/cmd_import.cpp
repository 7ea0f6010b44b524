// posectl import IN -o OUT.mcap: a pcap/pcapng Velodyne capture, a can-utils candump log or a
// ROS 1 bag (format 2.0) as a posed MCAP recording for `posed --replay` (docs/import.md). The
// input kind comes from its first bytes, never from its name. Progress on stderr about once a
// second; a summary with units at the end.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <string>

#include "drivers/recording/raw_channels.hpp"
#include "drivers/recording/ros1_bag_records.hpp"
#include "tools/posectl/commands.hpp"
#include "tools/posectl/import.hpp"

namespace posed::posectl {

namespace import {

std::map<std::string, std::string> default_topic_map() {
  // M2DGR's topic names (its README): VLP-32C cloud (velodyne_pointcloud layout), Handsfree A9
  // IMU, D435i colour and IMU, PLUG 617 thermal (8-bit, stamped on the host at arrival).
  return {{"/velodyne_points", "lidar"},
          {"/handsfree/imu", "imu"},
          {"/camera/color/image_raw", "visible"},
          {"/thermal_image_raw", "thermal"},
          {"/camera/imu", "realsense_imu"}};
}

std::map<std::string, std::string> recording_metadata(const ImportOptions& options,
                                                      const std::string& log_time_clock) {
  namespace raw = drivers::recording::raw;
  // The input's clock is the recording's "host" clock: wall time already (pcap, candump) or the
  // bag's ROS time, so replayed poses are stamped in the input's own time base.
  return {{std::string(raw::kHostToWallKey), "0"},
          {"log_time_clock", log_time_clock},
          {"imported_from", options.in_path},
          {"importer", "posectl import"}};
}

InputKind detect_input(const std::string& path, std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    what = "cannot open: " + std::string(std::strerror(errno));
    return InputKind::kUnknown;
  }
  std::string head(64, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::uint32_t magic = 0;
  if (head.size() >= 4) std::memcpy(&magic, head.data(), 4);
  // pcap (µs or ns resolution, either byte order) and pcapng's Section Header Block.
  for (const std::uint32_t m : {0xa1b2c3d4u, 0xd4c3b2a1u, 0xa1b23c4du, 0x4d3cb2a1u, 0x0a0d0d0au}) {
    if (head.size() >= 4 && magic == m) return InputKind::kPcap;
  }
  if (head.rfind("#ROSBAG V", 0) == 0 || head.rfind("#ROSRECORD V", 0) == 0) {
    return InputKind::kRos1Bag;  // the reader names versions other than 2.0
  }
  // candump -l: "(1600000000.123456) can0 123#DEADBEEF"
  if (head.size() > 3 && head[0] == '(') {
    const std::size_t close = head.find(')');
    const std::size_t dot = head.find('.');
    if (close != std::string::npos && dot != std::string::npos && dot < close &&
        head.find_first_not_of("0123456789.", 1) == close) {
      return InputKind::kCandump;
    }
  }
  std::string hex, text;
  for (std::size_t i = 0; i < std::min<std::size_t>(16, head.size()); ++i) {
    char b[4];
    std::snprintf(b, sizeof b, "%02x ", static_cast<unsigned char>(head[i]));
    hex += b;
    const auto c = static_cast<unsigned char>(head[i]);
    text += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '.';
  }
  if (!hex.empty()) hex.pop_back();
  what = head.empty() ? "the file is empty" : "its first bytes are " + hex + " (\"" + text + "\")";
  if (head.size() >= 8 && std::memcmp(head.data(), "\x89MCAP0\r\n", 8) == 0) {
    what += ": already an MCAP recording";
  }
  return InputKind::kUnknown;
}

Progress::Progress(std::string what)
    : what_(std::move(what)), start_(std::chrono::steady_clock::now()), last_(start_) {}

void Progress::update(std::uint64_t done, std::uint64_t total, std::uint64_t messages) {
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::seconds(1)) return;
  last_ = now;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  if (total > 0) {
    std::fprintf(
        stderr, "posectl import: %s: %.0f %% (%.1f of %.1f MB), %llu messages, %.1f MB/s\n",
        what_.c_str(), 100.0 * static_cast<double>(done) / static_cast<double>(total),
        static_cast<double>(done) * 1e-6, static_cast<double>(total) * 1e-6,
        static_cast<unsigned long long>(messages), static_cast<double>(done) * 1e-6 / elapsed_s);
  } else {
    std::fprintf(stderr, "posectl import: %s: %llu messages, %.0f s\n", what_.c_str(),
                 static_cast<unsigned long long>(messages), elapsed_s);
  }
}

}  // namespace import

namespace {

std::uint64_t file_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  return in ? static_cast<std::uint64_t>(in.tellg()) : 0;
}

void print_summary(const import::ImportOptions& options, const import::ImportResult& r,
                   double elapsed_s) {
  const std::uint64_t in_bytes = r.input_bytes > 0 ? r.input_bytes : file_size(options.in_path);
  const std::uint64_t out_bytes = file_size(options.out_path);
  std::printf("posectl import: %s %s (%.2f MB) -> %s (%.2f MB) in %.2f s (%.1f MB/s)\n",
              r.kind.c_str(), options.in_path.c_str(), static_cast<double>(in_bytes) * 1e-6,
              options.out_path.c_str(), static_cast<double>(out_bytes) * 1e-6, elapsed_s,
              elapsed_s > 0 ? static_cast<double>(in_bytes) * 1e-6 / elapsed_s : 0.0);
  const double span_s =
      r.messages > 0 ? static_cast<double>(r.last_log_ns - r.first_log_ns) * 1e-9 : 0.0;
  std::printf("  %llu messages on %zu channels, spanning %.3f s of log time\n",
              static_cast<unsigned long long>(r.messages), r.channels.size(), span_s);
  std::size_t width = 5;
  for (const auto& c : r.channels) width = std::max(width, c.topic.size());
  std::printf("  %-*s %10s %12s  %-8s %s\n", static_cast<int>(width), "topic", "messages",
              "bytes [B]", "stream", "type / wire format");
  for (const auto& c : r.channels) {
    std::printf("  %-*s %10llu %12llu  %-8s %s\n", static_cast<int>(width), c.topic.c_str(),
                static_cast<unsigned long long>(c.messages),
                static_cast<unsigned long long>(c.bytes), c.stream.empty() ? "-" : c.stream.c_str(),
                c.type.c_str());
  }
  std::set<std::string> streams;
  for (const auto& c : r.channels) {
    if (!c.stream.empty()) streams.insert(c.stream);
  }
  std::string list;
  for (const auto& s : streams) list += (list.empty() ? "" : ", ") + s;
  std::printf("  posed streams: %s%s\n", list.empty() ? "none" : list.c_str(),
              streams.count("imu") ? "" : " (posed --replay needs an imu stream)");
  for (const auto& n : r.notes) std::printf("  note: %s\n", n.c_str());
  for (const auto& w : r.warnings) std::printf("  warning: %s\n", w.c_str());
}

}  // namespace

int run_import(int argc, char** argv) {
  CLI::App app{
      "Turns a capture into a posed MCAP recording that `posed --replay` and `posectl export` "
      "take.\nThe input kind is detected from its first bytes:\n"
      "  pcap/pcapng   Velodyne UDP packets -> /posed/raw/lidar (data port) and\n"
      "                /posed/raw/lidar/1 (position port), as `posed --record` writes them\n"
      "  candump log   can-utils `candump -l` -> /posed/raw/imu (Linux CAN frames)\n"
      "  ROS 1 bag     every connection kept as a ros1 channel on its topic (ros1msg schema);\n"
      "                topics in the topic map also feed a posed stream. Default map (M2DGR):\n"
      "                /velodyne_points=lidar /handsfree/imu=imu /camera/color/image_raw=visible\n"
      "                /thermal_image_raw=thermal /camera/imu=realsense_imu\n"
      "Log times are the input's own clock (capture time, bag receive time), publish times the\n"
      "messages' header stamps; the recording's host-to-wall offset is 0, so replayed poses carry\n"
      "the input's time base. See docs/import.md.",
      "posectl import"};
  import::ImportOptions options;
  std::vector<std::string> topic_map;
  std::string compression = "lz4";
  int data_port = 2368, position_port = 8308;
  app.add_option("IN", options.in_path, "pcap/pcapng capture, candump log or ROS 1 bag")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("-o,--output", options.out_path, "MCAP recording to write")->required();
  app.add_option("--topic-map", topic_map,
                 "TOPIC=STREAM: feed a bag topic to a posed stream (lidar, imu, visible, "
                 "thermal, realsense_imu); adds to or overrides the default map; TOPIC= removes "
                 "a default. Repeatable.")
      ->expected(1)  // one TOPIC=STREAM per flag, so a positional after it stays positional
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app.add_option("--data-port", data_port, "Velodyne data port (pcap)")
      ->check(CLI::Range(1, 65535));
  app.add_option("--position-port", position_port, "Velodyne position port (pcap)")
      ->check(CLI::Range(1, 65535));
  app.add_option("--compression", compression, "MCAP chunk compression")
      ->check(CLI::IsMember({"lz4", "zstd", "none"}));
  CLI11_PARSE(app, argc, argv);

  options.topic_map = import::default_topic_map();
  for (const std::string& entry : topic_map) {
    const std::size_t eq = entry.find('=');
    if (eq == std::string::npos || eq == 0) {
      std::fprintf(stderr, "posectl import: --topic-map %s: expected TOPIC=STREAM\n",
                   entry.c_str());
      return 2;
    }
    const std::string stream = entry.substr(eq + 1);
    if (stream.find('/') != std::string::npos) {
      std::fprintf(stderr, "posectl import: --topic-map %s: a stream name has no '/'\n",
                   entry.c_str());
      return 2;
    }
    options.topic_map[entry.substr(0, eq)] = stream;
  }
  options.data_port = static_cast<std::uint16_t>(data_port);
  options.position_port = static_cast<std::uint16_t>(position_port);
  drivers::recording::parse_compression(compression, options.writer.compression);
  options.writer.library = "posectl import";

  std::string what;
  const import::InputKind kind = import::detect_input(options.in_path, what);
  if (kind == import::InputKind::kUnknown) {
    std::fprintf(stderr,
                 "posectl import: %s: not a recognised input: %s; expected a pcap/pcapng "
                 "capture, a can-utils candump log or a ROS 1 bag (#ROSBAG V2.0)\n",
                 options.in_path.c_str(), what.c_str());
    return 1;
  }
  const auto start = std::chrono::steady_clock::now();
  import::ImportResult result;
  int rc = 1;
  switch (kind) {
    case import::InputKind::kPcap:
      rc = import::import_pcap(options, result);
      break;
    case import::InputKind::kCandump:
      rc = import::import_candump(options, result);
      break;
    case import::InputKind::kRos1Bag:
      rc = import::import_ros1_bag(options, result);
      break;
    case import::InputKind::kUnknown:
      break;
  }
  if (rc != 0) return rc;
  print_summary(options, result,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return 0;
}

}  // namespace posed::posectl
