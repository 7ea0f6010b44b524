#pragma once
// Cuts the stream of decoded packets into scans (one rotation each) and writes them as LidarPoint
// arrays into PayloadPool buffers. Pure: no clock, no I/O; packets and their device times in,
// LidarScans out. Every decoded point lands in exactly one scan: scans are cut between firings
// (never inside one), at the first firing whose azimuth has passed `cut_azimuth_cdeg`.
//
// Lost packets are detected from the device time between packets (the packet period is
// firing_count × firing period: 663.552 µs single, 331.776 µs dual for the VLP-32C); a gap longer
// than a rotation still cuts, because the expected rotation (rpm × gap) tells how far the head
// turned while nothing arrived.

#include <array>
#include <cstdint>

#include "core/measurements.hpp"
#include "core/payload_pool.hpp"
#include "core/time.hpp"
#include "drivers/velodyne/packet_decoder.hpp"

namespace posed::drivers::velodyne {

struct ScanAssemblerConfig {
  /// scan boundary, Velodyne azimuth (clockwise from the x axis seen from above) [0.01°]
  std::uint32_t cut_azimuth_cdeg = 0;
  /// a scan is closed after this long whatever the azimuth (stalled head); ≤ 2 s so that
  /// LidarPoint::offset_ns fits [ns]
  Duration max_scan_duration = Duration::from_ms(500);
  /// host = device + this, for LidarScan's host stamps until ClockSync supplies a mapping [ns]
  Duration host_minus_device{};
};

/// What the assembler knows about one scan beyond the LidarScan itself.
struct ScanInfo {
  /// first firing in the scan, device clock
  DeviceTime device_start;
  /// last point's firing in the scan, device clock
  DeviceTime device_end;
  /// packets that contributed firings
  std::uint32_t packets = 0;
  /// packets presumed lost inside the scan (from device-time gaps)
  std::uint32_t missing_packets = 0;
  /// points that did not fit the pool buffer
  std::uint32_t points_overflow = 0;
  /// the scan began / ended by crossing the cut azimuth (not at start-up, a time jump or the
  /// duration limit); a full rotation has both and no missing packets
  bool starts_at_cut = false;
  bool ends_at_cut = false;
  bool complete() const { return starts_at_cut && ends_at_cut && missing_packets == 0; }
};

struct AssembledScan {
  LidarScan scan;
  ScanInfo info;
};

struct ScanAssemblerCounters {
  std::uint64_t packets = 0;
  std::uint64_t scans = 0;
  /// scans whose points were discarded because the pool had no free buffer
  std::uint64_t scans_no_buffer = 0;
  /// finished scans overwritten because nobody popped them
  std::uint64_t scans_unread = 0;
  std::uint64_t points = 0;
  std::uint64_t points_overflow = 0;
  /// device-time gaps between packets, and the packets they imply were lost
  std::uint64_t gaps = 0;
  std::uint64_t missing_packets = 0;
  /// device time went backwards (sensor restart, recording spliced)
  std::uint64_t time_jumps = 0;
  /// packets left out because their device time was the previous packet's (a duplicated
  /// datagram, or a late one stamped with the newest device time by ScanBuilder)
  std::uint64_t repeated_packets = 0;
};

class ScanAssembler {
 public:
  /// The pool's buffers should hold a scan: ~58k points single, ~116k dual for the VLP-32C at
  /// 10 Hz, times sizeof(LidarPoint).
  ScanAssembler(PayloadPool& pool, ScanAssemblerConfig config = {});

  /// Adds one decoded packet whose first firing happened at `packet_time`.
  void add(const DecodedPacket& packet, DeviceTime packet_time);
  /// Closes the open scan (end of stream); it is then available from pop().
  void flush();
  /// Takes the oldest finished scan; false when none is ready.
  bool pop(AssembledScan& out);
  /// For ClockSync: the offset used for later scans' host stamps.
  void set_host_minus_device(Duration d) { config_.host_minus_device = d; }

  const ScanAssemblerCounters& counters() const { return counters_; }

 private:
  bool crossed_cut(std::uint32_t prev_az, std::uint32_t az, std::int64_t dt_ns) const;
  void open(DeviceTime start, bool at_cut);
  void close(bool at_cut);

  PayloadPool& pool_;
  ScanAssemblerConfig config_;
  ScanAssemblerCounters counters_;

  // the scan being filled
  bool open_ = false;
  PayloadPool::Lease lease_;
  LidarPoint* points_ = nullptr;
  std::uint32_t capacity_ = 0;
  std::uint32_t count_ = 0;
  ScanInfo info_;
  std::uint64_t next_sequence_ = 0;

  // continuity
  bool have_packet_ = false;
  DeviceTime last_packet_time_;
  bool have_firing_ = false;
  std::uint32_t last_azimuth_cdeg_ = 0;
  DeviceTime last_firing_time_;
  /// latest rotation speed seen [0.01° per ns]
  double rate_cdeg_per_ns_ = 0.0;

  // finished scans waiting for pop(): a packet closes at most two (a cut and a time limit)
  static constexpr std::size_t kReady = 4;
  std::array<AssembledScan, kReady> ready_{};
  std::size_t ready_head_ = 0;
  std::size_t ready_count_ = 0;
};

}  // namespace posed::drivers::velodyne
