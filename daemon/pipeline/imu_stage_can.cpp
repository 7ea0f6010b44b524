// The IMU stage's decoder for Linux CAN frames (wire format linux-can-frame): one struct
// can_frame / canfd_frame per chunk, from a live SocketCanSource, a recording of one, or a
// candump log imported with `posectl import` (docs/import.md). Which frame carries which field
// is data, not code: imu.can_mapping (config/imu-can-example.yaml), checked at load by the
// decoder's own validate(). A completed sample is in the sensor's axes and SI units; it is
// rotated into the IMU frame by imu.R_imu_sensor exactly as the A9's frames are.
//
// Time: with a counter field mapped (a µs counter, e.g. a u32 that wraps like the A9's), the
// counter is the device stamp and goes through the stage's ClockSync (imu.clock_kind,
// counter_us_32bit for such a counter) against the frame's arrival time. Without one, or with
// imu.clock_kind none, a sample is stamped with the arrival of its completing frame minus
// imu.clock_latency_s.
//
// Malformed input (a chunk that is no kernel CAN frame, a mapped field beyond the frame's
// length, a completing frame whose sample misses fields) is counted as malformed and skipped;
// frames of other IDs on the bus are not the IMU's and are ignored without a count.

#include "daemon/pipeline/imu_stage.hpp"
#include "drivers/common/log.hpp"
#include "drivers/imu/can_frame.hpp"

namespace posed::pipeline {

namespace can = drivers::can;

void ImuStage::count_malformed_can(const char* what, std::size_t bytes) {
  if (counters_.malformed.fetch_add(1, std::memory_order_relaxed) == 0) {
    POSED_LOG_WARN("imu: malformed CAN input (%s, %zu B): skipped (said once)", what, bytes);
  }
}

void ImuStage::on_can_frame(const drivers::RawChunk& chunk) {
  if (!can_mapped_) {
    // Without a mapping nothing says which frames are the IMU's: a config problem, said once.
    counters_.undecodable.fetch_add(1, std::memory_order_relaxed);
    if (!can_unmapped_said_) {
      can_unmapped_said_ = true;
      POSED_LOG_ERROR(
          "imu: CAN frames (wire format linux-can-frame) but no imu.can_mapping in the "
          "configuration says which of them carry the IMU's fields: frames skipped (see "
          "config/imu-can-example.yaml; a recording made by posed carries the mapping it was "
          "made with: posed --replay FILE --recorded-config)");
    }
    return;
  }
  can::CanFrame frame;
  if (!can::from_kernel_bytes(
          std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(chunk.bytes.data()),
                                        chunk.bytes.size()),
          frame)) {
    count_malformed_can("not a struct can_frame/canfd_frame", chunk.bytes.size());
    return;
  }
  can::CanImuReading reading;
  switch (can_decoder_.decode(frame, reading)) {
    case can::CanImuStatus::kIgnored:
    case can::CanImuStatus::kPartial:
      return;
    case can::CanImuStatus::kTooShort:
      count_malformed_can("a mapped field lies beyond the frame's data length", frame.len);
      return;
    case can::CanImuStatus::kIncomplete:
      count_malformed_can("the completing frame came before every mapped field", frame.len);
      return;
    case can::CanImuStatus::kSample:
      break;
  }
  const bool device_clock = reading.has_counter && clock_.config().kind != DeviceClockKind::kNone;
  if (!device_clock && !can_clock_said_ && clock_.config().kind != DeviceClockKind::kNone) {
    can_clock_said_ = true;
    POSED_LOG_NOTICE(
        "imu: imu.can_mapping maps no counter: samples are stamped with their arrival time "
        "(imu.clock_kind ignored)");
  }
  HostTime stamp;
  DeviceTime device_stamp;
  if (device_clock) {
    stamp = clock_.map_raw(reading.counter_us, chunk.host_receive);
    log_clock_event("imu", clock_.last_event());
    device_stamp = clock_.status().last_device_stamp;
  } else {
    stamp = chunk.host_receive - clock_.config().latency;
  }
  push(can::to_imu_sample(reading, mounting_, stamp, device_stamp));
}

}  // namespace posed::pipeline
