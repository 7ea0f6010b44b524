#include "drivers/velodyne/scan_builder.hpp"

namespace posed::drivers::velodyne {

std::size_t max_points_per_scan(double rpm) {
  // Dual return: 3014 packets/s of 384 points.
  return static_cast<std::size_t>(1.2 * 3014.0 * 384.0 * 60.0 / rpm);
}

ScanBuilder::ScanBuilder(Calibration calibration, const ScanBuilderConfig& config,
                         PayloadPool& pool)
    : decoder_(std::move(calibration), config.decoder),
      clock_(config.clock),
      assembler_(pool, config.assembler),
      packet_(std::make_unique<DecodedPacket>()) {}

DecodeStatus ScanBuilder::add_data(std::span<const std::byte> payload, HostTime arrival) {
  const DecodeStatus status = decoder_.decode(payload, *packet_);
  if (status != DecodeStatus::kOk) return status;
  const HostTime stamp = clock_.map_raw(packet_->device_time_us, arrival);
  // A stamp the clock could not place (a corrupt one; the packet has no checksum) would put its
  // points in another scan, or tear the one being assembled: left out, counted by the clock.
  if (clock_.last_event() == ClockEvent::kOutlier) return status;
  const DeviceTime device_stamp = clock_.status().last_device_stamp;
  // The assembler stamps points as device time + this offset: ClockSync's mapping, per packet.
  assembler_.set_host_minus_device(stamp - HostTime::from_ns(device_stamp.ns));
  assembler_.add(*packet_, device_stamp);
  return status;
}

std::optional<PpsStatus> ScanBuilder::add_position(std::span<const std::byte> payload) {
  PositionPacket position;
  if (parse_position_packet(payload, position) == PositionStatus::kWrongSize) return std::nullopt;
  return position.pps;
}

}  // namespace posed::drivers::velodyne
