#pragma once
// Velodyne packets in, host-stamped scans out: the packet decoder, ClockSync (the device's µs past
// the hour onto the host clock, per packet) and the scan assembler in one piece, as the daemon's
// lidar stage, `posectl bench lio` and the tests use them. Pure: the caller supplies the bytes and
// their host arrival times; no clock is read, no I/O.

#include <memory>
#include <optional>
#include <span>

#include "core/payload_pool.hpp"
#include "core/sync/clock_sync.hpp"
#include "drivers/velodyne/calibration.hpp"
#include "drivers/velodyne/packet_decoder.hpp"
#include "drivers/velodyne/position_packet.hpp"
#include "drivers/velodyne/scan_assembler.hpp"

namespace posed::drivers::velodyne {

struct ScanBuilderConfig {
  DecoderConfig decoder;
  ClockSyncConfig clock{.kind = DeviceClockKind::kUsPastHour, .nominal_rate_hz = 1507.0};
  ScanAssemblerConfig assembler;
};

class ScanBuilder {
 public:
  /// `calibration` empty: the manual's table for the model seen. Scans go into `pool`.
  ScanBuilder(Calibration calibration, const ScanBuilderConfig& config, PayloadPool& pool);

  /// One data-port payload received at `arrival`; kOk when it was decoded (scans that it
  /// completed are then ready in pop()).
  DecodeStatus add_data(std::span<const std::byte> payload, HostTime arrival);
  /// One position-port payload: its PPS status (locked: device time is GPS-aligned); nullopt
  /// when it is not a position packet.
  std::optional<PpsStatus> add_position(std::span<const std::byte> payload);
  /// The next finished scan, oldest first.
  bool pop(AssembledScan& out) { return assembler_.pop(out); }
  /// End of stream: closes the scan in progress (then available from pop()).
  void flush() { assembler_.flush(); }

  const ClockSync& clock() const { return clock_; }
  const PacketDecoder& decoder() const { return decoder_; }
  const ScanAssembler& assembler() const { return assembler_; }

 private:
  PacketDecoder decoder_;
  ClockSync clock_;
  ScanAssembler assembler_;
  /// heap, not stack: 384 decoded points
  std::unique_ptr<DecodedPacket> packet_;
};

/// Room for one scan at `rpm` in dual-return mode with a 20 % margin (slow rotation, late cut)
/// [points].
std::size_t max_points_per_scan(double rpm);

}  // namespace posed::drivers::velodyne
