#pragma once
// Writes small MCAP recordings with raw channels laid out as posed records them
// (drivers/recording/raw_channels.hpp), message by message with chosen log times, for the HIL
// tests. Each payload names its channel and index, so a test can tell what it received.

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "drivers/recording/mcap_writer.hpp"
#include "drivers/recording/raw_channels.hpp"

namespace posed::hil::test {

struct RawMessage {
  /// index into the channels passed to write_recording()
  std::size_t channel = 0;
  /// [ns]
  std::int64_t log_ns = 0;
  std::vector<std::byte> bytes;
};

struct RawChannelSpec {
  std::string stream;
  std::string wire_format;
  std::uint32_t source_channel = 0;
  /// not a raw channel: a CDR pose topic (what posed --record also writes)
  bool pose = false;
};

/// A payload: `size` bytes starting with the channel and the index, then a counting pattern that
/// includes the bytes a tty would mangle in cooked mode (CR, LF, ^C, XON/XOFF, DEL).
inline std::vector<std::byte> payload(std::size_t channel, std::uint32_t index,
                                      std::size_t size = 32) {
  std::vector<std::byte> p(size);
  static constexpr std::uint8_t kAwkward[] = {0x0d, 0x0a, 0x03, 0x11, 0x13, 0x7f, 0x04, 0x1a};
  for (std::size_t i = 0; i < size; ++i) {
    p[i] = static_cast<std::byte>(i < sizeof kAwkward ? kAwkward[i] : (i * 31 + index) & 0xFF);
  }
  p[size - 3] = static_cast<std::byte>(channel);
  p[size - 2] = static_cast<std::byte>(index & 0xFF);
  p[size - 1] = static_cast<std::byte>(index >> 8);
  return p;
}

/// Writes `messages` in the given (file) order; false + error text on failure.
inline bool write_recording(const std::string& path, const std::vector<RawChannelSpec>& channels,
                            const std::vector<RawMessage>& messages, std::string& error,
                            std::int64_t host_to_wall_ns = 0, std::size_t chunk_bytes = 4096) {
  namespace rec = drivers::recording;
  rec::McapWriterOptions options;
  options.chunk_size_bytes = chunk_bytes;
  options.fsync_on_close = false;
  rec::McapWriter w;
  if (!w.open(path, options, error)) return false;
  if (host_to_wall_ns != 0) {
    w.write_metadata(rec::raw::kMetadataName,
                     {{std::string(rec::raw::kHostToWallKey), std::to_string(host_to_wall_ns)}});
  }
  std::vector<std::uint16_t> ids;
  for (const auto& c : channels) {
    if (c.pose) {
      ids.push_back(w.add_channel("/posed/pose", "cdr", 0, {}));
      continue;
    }
    ids.push_back(w.add_channel(
        rec::raw::topic(c.stream, c.source_channel), rec::raw::kMessageEncoding, 0,
        {{std::string(rec::raw::kStreamKey), c.stream},
         {std::string(rec::raw::kWireFormatKey), c.wire_format},
         {std::string(rec::raw::kSourceChannelKey), std::to_string(c.source_channel)}}));
  }
  std::uint32_t seq = 0;
  for (const auto& m : messages) {
    const auto t = static_cast<std::uint64_t>(m.log_ns);
    if (!w.write_message(ids[m.channel], seq++, t, t, m.bytes)) {
      error = w.error();
      return false;
    }
  }
  if (!w.close()) {
    error = w.error();
    return false;
  }
  return true;
}

/// The rig of a posed recording: imu (A9 serial), lidar data and position, a camera the HIL replay
/// has no output for, and the poses.
inline std::vector<RawChannelSpec> rig_channels() {
  return {{"imu", "a9-serial", 0, false},
          {"lidar", "velodyne-udp-data", 0, false},
          {"lidar", "velodyne-udp-position", 1, false},
          {"visible", "yuyv", 0, false},
          {"", "", 0, true}};
}

/// A per-test directory under the system temp directory, removed at the end.
class TempDir {
 public:
  explicit TempDir(const std::string& tag)
      : path_(std::filesystem::temp_directory_path() /
              ("posed_hil_" + tag + "_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace posed::hil::test
