// libFuzzer target: IMUs over CAN, from the bytes to the sample. Every input is read both ways
// posed meets CAN: as a candump log (one parse_candump_line per line) and as the kernel frames a
// CAN_RAW socket or a recording hands over (16-byte can_frame, 72-byte canfd_frame, back to
// back). Contracts beyond "no crash, no UB":
//  - a refused line always says why;
//  - a parsed frame survives the kernel byte form unchanged (to_kernel_bytes/from_kernel_bytes);
//  - every frame fed to a CanImuDecoder is counted exactly once, and samples are finite.
// Two mappings decode every frame: the example IMU's (config/imu-can-example.yaml) and a wide
// one with 29-bit IDs, CAN FD offsets, big-endian f32 fields and a scaled f32 counter.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>
#include <string_view>

#include "drivers/imu/can_frame.hpp"
#include "drivers/imu/can_imu_mapping.hpp"
#include "drivers/imu/candump_log.hpp"

namespace can = posed::drivers::can;

namespace {

can::CanImuMapping example_mapping() {
  can::CanImuMapping m;
  m.complete_on_id = 0x182;
  m.fields = {{0x180, false, can::ImuField::kCounter, 0, can::FieldType::kU32, false, 1.0, 0.0},
              {0x181, false, can::ImuField::kGyroX, 0, can::FieldType::kI16, false, 1.745e-4, 0},
              {0x181, false, can::ImuField::kGyroY, 2, can::FieldType::kI16, false, 1.745e-4, 0},
              {0x181, false, can::ImuField::kGyroZ, 4, can::FieldType::kI16, false, 1.745e-4, 0},
              {0x182, false, can::ImuField::kAccelX, 0, can::FieldType::kI16, false, 9.8e-3, 0},
              {0x182, false, can::ImuField::kAccelY, 2, can::FieldType::kI16, false, 9.8e-3, 0},
              {0x182, false, can::ImuField::kAccelZ, 4, can::FieldType::kI16, false, 9.8e-3, 0}};
  return m;
}

can::CanImuMapping wide_mapping() {
  can::CanImuMapping m;
  m.complete_on_id = 0x123;
  m.complete_on_extended = false;
  m.fields = {{0x12345678, true, can::ImuField::kGyroX, 0, can::FieldType::kF32, true, 1.0, 0.0},
              {0x12345678, true, can::ImuField::kGyroY, 4, can::FieldType::kF32, true, -1.0, 0.5},
              {0x12345678, true, can::ImuField::kGyroZ, 60, can::FieldType::kI32, true, 1e-6, 0.0},
              {0x123, false, can::ImuField::kAccelX, 0, can::FieldType::kU8, false, 0.1, 0.0},
              {0x123, false, can::ImuField::kAccelY, 1, can::FieldType::kI8, false, 0.1, 0.0},
              {0x123, false, can::ImuField::kAccelZ, 2, can::FieldType::kU16, true, 0.01, 0.0},
              {0x123, false, can::ImuField::kCounter, 4, can::FieldType::kF32, false, 1e6, 0.0}};
  return m;
}

void check(bool ok) {
  if (!ok) std::abort();
}

struct Decoders {
  can::CanImuDecoder example{example_mapping()};
  can::CanImuDecoder wide{wide_mapping()};
  std::uint64_t fed = 0;

  void feed(const can::CanFrame& f) {
    ++fed;
    for (can::CanImuDecoder* d : {&example, &wide}) {
      can::CanImuReading r;
      if (d->decode(f, r) == can::CanImuStatus::kSample) {
        // Counters are integers whatever the bytes: the cast to u64 must stay defined.
        volatile std::uint64_t sink = r.counter_us;
        (void)sink;
      }
      const can::CanImuCounters& c = d->counters();
      // kPartial is not counted; everything else is, once.
      check(c.samples + c.ignored + c.too_short + c.incomplete <= fed);
    }
  }
};

void round_trip(const can::CanFrame& f) {
  std::uint8_t k[can::kCanFdMtu];
  const std::size_t n = can::to_kernel_bytes(f, k);
  if (n == 0) return;
  can::CanFrame back;
  check(can::from_kernel_bytes(std::span<const std::uint8_t>(k, n), back));
  check(back.id == f.id && back.error == f.error && back.fd == f.fd && back.len == f.len);
  // An error frame's ID is its class bits: the kernel form drops the EFF/RTR flags.
  if (f.error) return;
  check(back.extended == f.extended && back.remote == f.remote);
  if (!f.remote) {
    for (std::size_t i = 0; i < f.len; ++i) check(back.data[i] == f.data[i]);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // As a candump log.
  Decoders from_log;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t nl = std::min(text.find('\n', at), text.size());
    const std::string_view line = text.substr(at, nl - at);
    at = nl + 1;
    can::CandumpRecord record;
    std::string error;
    if (can::parse_candump_line(line, record, error)) {
      check(record.interface[0] != '\0');
      round_trip(record.frame);
      from_log.feed(record.frame);
    } else {
      check(!error.empty());
    }
  }
  // As kernel frames, classic and FD.
  for (const std::size_t mtu : {can::kCanMtu, can::kCanFdMtu}) {
    Decoders from_socket;
    for (std::size_t off = 0; off + mtu <= size; off += mtu) {
      can::CanFrame f;
      if (!can::from_kernel_bytes(std::span<const std::uint8_t>(data + off, mtu), f)) continue;
      round_trip(f);
      from_socket.feed(f);
    }
  }
  return 0;
}
