#pragma once
// Hardware-in-the-loop replay (`posectl replay`): the HilPlaylist's messages go out on their
// outputs (UdpEmitter, PtyEmitter) at their recorded times on the Pacer's absolute schedule, and
// how late each one left is measured per output. One thread sends everything, in log-time order,
// so the lidar and the IMU keep their recorded interleaving.
//
// Threading: run() on one thread; status() and request_stop() from any other.

#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <string>

#include "tools/hil/hil_faults.hpp"
#include "tools/hil/hil_playlist.hpp"
#include "tools/hil/iio_emitter.hpp"
#include "tools/hil/lateness_histogram.hpp"
#include "tools/hil/pacer.hpp"
#include "tools/hil/pty_emitter.hpp"
#include "tools/hil/udp_emitter.hpp"

namespace posed::hil {

struct HilReplayOptions {
  HilPlaylistOptions playlist;
  /// 1 = recorded timing, 2 = twice as fast; > 0
  double rate = 1.0;
  UdpTarget udp;
  /// symlink to the pty ("" = none; the pty's own name is then the only way to it)
  std::string pty_link;
  /// where the D435i's IMU goes as IIO devices (iio_emitter.hpp); with playlist.iio
  std::string iio_dir;
  /// the schedule's first message is due this long after run() starts sending, so setup costs
  /// do not show as lateness
  Duration lead = Duration::from_ms(100);
  /// transport faults laid over what is sent (hil_faults.hpp)
  std::vector<HilFault> faults;
};

/// Outputs, in the order of HilReplayStatus::lateness.
inline constexpr std::array kHilOutputs = {HilOutput::kUdpData, HilOutput::kUdpPosition,
                                           HilOutput::kSerial, HilOutput::kIio};

struct HilReplayStatus {
  UdpChannelCounters udp_data;
  UdpChannelCounters udp_position;
  PtyCounters pty;
  IioCounters iio;
  /// messages handed to each output of kHilOutputs (sent or not)
  std::array<std::uint64_t, kHilOutputs.size()> messages{};
  /// lateness per output of kHilOutputs (send time minus due time)
  std::array<LatenessHistogram, kHilOutputs.size()> lateness;
  /// the schedule: log time anchor_log_ns is due at host time anchor_host (once started)
  bool started = false;
  HostTime anchor_host;
  std::int64_t anchor_log_ns = 0;
  /// log time of the last message sent, shifted by loop passes [ns]
  std::int64_t last_log_ns = 0;
  /// log time the first pass ends at, from the summary; 0 when unknown [ns]
  std::int64_t end_log_ns = 0;
  std::uint64_t passes = 0;
  bool finished = false;
  HilFaultCounts faults;
};

class HilReplay {
 public:
  explicit HilReplay(HilReplayOptions options);

  /// Opens the recording and the outputs it needs (UDP socket, pty and symlink). false + error.
  /// Call before run(); playlist(), pty() and udp() are for the thread that calls run(), or
  /// for after it returned.
  bool open(std::string& error);
  /// Sends the playlist on schedule until it ends or request_stop(); blocks.
  void run();
  void request_stop() { stop_.store(true, std::memory_order_relaxed); }
  /// set by request_stop(), for waits outside run() (the pty reader)
  const std::atomic<bool>& stop_flag() const { return stop_; }

  HilReplayStatus status() const;
  const HilPlaylist& playlist() const { return playlist_; }
  /// null when the recording sends nothing to a pty
  PtyEmitter* pty() { return pty_.get(); }
  /// null when the recording sends nothing over UDP
  const UdpEmitter* udp() const { return udp_.get(); }
  /// null when nothing goes to IIO devices
  const IioEmitter* iio() const { return iio_.get(); }
  const HilReplayOptions& options() const { return options_; }

 private:
  static std::size_t slot(HilOutput output);
  void send(const HilMessage& m);
  /// Sends `m` as the faults in force at `t_s` say (dropped, corrupted, twice, or held back).
  void send_faulted(HilMessage& m, double t_s);
  /// Unplugs or plugs the pty back in as the faults say at `t_s`; sends what a delay held back
  /// once its window ended (all of it when `flush`).
  void apply_faults(double t_s, bool flush);

  HilReplayOptions options_;
  HilPlaylist playlist_;
  Pacer pacer_;
  std::unique_ptr<UdpEmitter> udp_;
  std::unique_ptr<PtyEmitter> pty_;
  std::unique_ptr<IioEmitter> iio_;
  std::atomic<bool> stop_{false};
  HilFaults faults_;
  /// log time of the first message sent: the faults' time origin [ns]
  std::int64_t first_log_ns_ = 0;
  /// messages a delay fault holds back, in order
  std::vector<HilMessage> held_;
  bool unplugged_ = false;

  mutable std::mutex mutex_;  // guards the fields below
  std::array<std::uint64_t, kHilOutputs.size()> messages_{};
  std::array<LatenessHistogram, kHilOutputs.size()> lateness_;
  bool started_ = false;
  std::int64_t last_log_ns_ = 0;
  std::int64_t end_log_ns_ = 0;
  std::uint64_t passes_ = 0;
  bool finished_ = false;
  HilFaultCounts fault_counts_;
};

}  // namespace posed::hil
