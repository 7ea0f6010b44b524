#pragma once
// What a hardware-in-the-loop replay sends, in what order: the raw channels of a recording
// (drivers/recording/raw_channels.hpp) that have a wire to go back onto, by wire format:
//   velodyne-udp-data      -> UDP data port        (HilOutput::kUdpData)
//   velodyne-udp-position  -> UDP position port    (HilOutput::kUdpPosition)
//   a9-serial              -> the pty              (HilOutput::kSerial)
//   iio-hid-accel-3d/gyro  -> fake IIO devices     (HilOutput::kIio, only when asked)
// merged across channels in log-time order, with --start/--duration/--loop applied. Channels of
// other formats (camera frames, CAN) are listed with the reason they are not sent.
//
// The Recorder writes each channel in order but sorts only within the batches its thread drains,
// so the file can hold a message a few milliseconds "before" one already written on another
// channel; a reorder window of log time (default 1 s) restores the order without reading the
// whole file first. A damaged file plays up to the damage (damage() says where).

#include <cstdint>
#include <queue>
#include <string>
#include <string_view>
#include <vector>

#include "core/time.hpp"
#include "drivers/recording/mcap_reader.hpp"

namespace posed::hil {

enum class HilOutput : std::uint8_t { kNone, kUdpData, kUdpPosition, kSerial, kIio };

std::string_view to_string(HilOutput output);
/// The output a raw channel of `wire_format` goes to (kNone: no HIL output for it).
HilOutput output_for_wire_format(std::string_view wire_format);

struct HilPlaylistOptions {
  std::string path;
  /// skip this much log time after the first message sent
  Duration start = Duration::from_ns(0);
  /// send this much log time after the start; 0 = to the end
  Duration duration = Duration::from_ns(0);
  /// at the end, start again; log times keep increasing (each pass is shifted by its span plus
  /// one inter-message gap) so the schedule moves forward
  bool loop = false;
  /// leave out the UDP (lidar) or the serial (A9) outputs
  bool udp = true;
  bool serial = true;
  /// the D435i's IMU onto IIO devices (IioEmitter): only when a directory for them is given
  bool iio = false;
  /// how far out of log-time order the file may be [ns]
  Duration reorder_window = Duration::from_s(1);
};

struct HilChannel {
  std::uint16_t id = 0;
  std::string topic;
  std::string stream;
  std::string wire_format;
  std::uint32_t source_channel = 0;
  HilOutput output = HilOutput::kNone;
  /// sent (false: no output for its format, or its output was switched off)
  bool sent = false;
};

struct HilMessage {
  /// log time, shifted by the loop passes before it [ns]
  std::int64_t log_ns = 0;
  HilOutput output = HilOutput::kNone;
  /// index into HilPlaylist::channels()
  std::size_t channel = 0;
  std::vector<std::byte> bytes;
};

class HilPlaylist {
 public:
  /// Opens the recording and lists its raw channels (scanning the file once when it has no
  /// usable summary). false + `error` when it is not MCAP or holds nothing to send.
  bool open(const HilPlaylistOptions& options, std::string& error);
  /// The next message in log-time order; false at the end (or the damage).
  bool next(HilMessage& out);

  const std::vector<HilChannel>& channels() const { return channels_; }
  /// "" or where and why the recording ended early
  const std::string& damage() const { return damage_; }
  /// completed passes (with loop)
  std::uint64_t passes() const { return passes_; }
  /// log time the schedule starts at: the first message sent, plus --start [ns]; valid once
  /// next() returned a message
  std::int64_t begin_log_ns() const { return begin_log_ns_; }
  /// log time of the last message a pass sends, from the summary (0 when unknown) [ns]
  std::int64_t end_log_ns() const;
  /// wall minus host time of the recording (its "posed" metadata record), when known
  bool recorded_host_to_wall(HostToWall& out) const;

 private:
  struct Pending {
    std::int64_t log_ns;
    std::uint64_t order;  // read order: ties keep file order
    HilMessage message;
  };
  struct Later {
    bool operator()(const Pending& a, const Pending& b) const {
      return a.log_ns != b.log_ns ? a.log_ns > b.log_ns : a.order > b.order;
    }
  };

  bool read_one();  // one message from the file into the heap; false at the end of all passes
  bool end_pass();  // false when there is no next pass
  void note_damage();

  HilPlaylistOptions options_;
  drivers::recording::McapReader reader_;
  std::vector<HilChannel> channels_;
  std::vector<std::int64_t> channel_index_;  // MCAP channel id -> index in channels_, or -1
  std::priority_queue<Pending, std::vector<Pending>, Later> heap_;
  std::int64_t newest_in_heap_ns_ = 0;
  std::uint64_t order_ = 0;
  bool file_done_ = false;

  bool have_first_ = false;
  std::int64_t first_log_ns_ = 0;  // first message sent, file order, unshifted
  std::int64_t begin_log_ns_ = 0;
  std::int64_t last_log_ns_ = 0;  // newest of this pass, unshifted
  std::int64_t last_gap_ns_ = 0;  // between the two newest of this pass
  std::int64_t shift_ns_ = 0;
  std::uint64_t sent_this_pass_ = 0;
  std::uint64_t passes_ = 0;
  std::string damage_;
};

}  // namespace posed::hil
