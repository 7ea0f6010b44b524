#pragma once
// posectl import: turns captures made by other tools into posed MCAP recordings that `posed
// --replay` takes (docs/import.md). One importer per input kind, each in its own file:
//   import_raw.cpp   pcap/pcapng (Velodyne UDP) and candump logs: raw channels exactly as
//                    `posed --record` writes them (drivers/recording/raw_channels.hpp)
//   import_ros1.cpp  ROS 1 bags: every connection kept as a ros1 channel, mapped topics marked
//                    with the posed stream they feed

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "drivers/recording/mcap_writer.hpp"

namespace posed::posectl::import {

enum class InputKind { kPcap, kCandump, kRos1Bag, kUnknown };

/// What the first bytes of `path` say it is; `what` describes them for an error message.
InputKind detect_input(const std::string& path, std::string& what);

struct ImportOptions {
  std::string in_path;
  std::string out_path;
  drivers::recording::McapWriterOptions writer;
  /// ROS topic -> posed stream ("lidar", "imu", "visible", "thermal", "realsense_imu");
  /// an empty stream removes a default mapping
  std::map<std::string, std::string> topic_map;
  /// Velodyne UDP ports (pcap)
  std::uint16_t data_port = 2368;
  std::uint16_t position_port = 8308;
};

/// M2DGR's topics onto posed's streams (the default topic map).
std::map<std::string, std::string> default_topic_map();

/// One output channel in the summary.
struct ChannelSummary {
  std::string topic;
  std::string type;    ///< ROS type, or the raw wire format
  std::string stream;  ///< posed stream fed, "" for none
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;  ///< payload [B]
};

struct ImportResult {
  std::string kind;  ///< "pcap capture", "candump log", "ROS 1 bag"
  std::vector<ChannelSummary> channels;
  std::uint64_t messages = 0;
  std::uint64_t first_log_ns = 0, last_log_ns = 0;  ///< [ns]
  std::uint64_t input_bytes = 0;                    ///< [B]
  /// input left out: other ports, non-UDP frames, malformed lines, damaged chunks
  std::vector<std::string> notes;
  /// problems with the input (damage, skipped records), each naming its offset or line
  std::vector<std::string> warnings;
};

/// Prints progress to stderr about once a second (never for inputs read in under a second).
class Progress {
 public:
  explicit Progress(std::string what);
  /// `done`/`total` in bytes (total 0 when unknown), `messages` written so far.
  void update(std::uint64_t done, std::uint64_t total, std::uint64_t messages);

 private:
  std::string what_;
  std::chrono::steady_clock::time_point start_, last_;
};

/// Each returns 0 on success, else prints why (naming the file) and returns non-zero.
int import_pcap(const ImportOptions& options, ImportResult& result);
int import_candump(const ImportOptions& options, ImportResult& result);
int import_ros1_bag(const ImportOptions& options, ImportResult& result);

/// The "posed" Metadata record of an imported recording: its log times are the input's own
/// clock, so host-to-wall is 0 and replayed poses carry the input's time base.
std::map<std::string, std::string> recording_metadata(const ImportOptions& options,
                                                      const std::string& log_time_clock);

}  // namespace posed::posectl::import
