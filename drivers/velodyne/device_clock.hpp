#pragma once
// The Velodyne clock counts µs past the top of the hour and wraps every hour (manual 9.3.1.6
// "Timestamp"). This turns that counter into a monotonic DeviceTime [ns] by counting wraps; a
// position packet's GPRMC fix (position_packet.hpp) anchors hour 0 in UTC when ClockSync wants.

#include <cstdint>

#include "core/time.hpp"

namespace posed::drivers::velodyne {

class HourUnwrapper {
 public:
  /// Device time of `us_past_hour`, counting hours since the first stamp seen. A stamp within
  /// half an hour before the previous one is a late packet of the same hour, not a wrap.
  DeviceTime unwrap(std::uint32_t us_past_hour) {
    constexpr std::int64_t kHourUs = 3'600'000'000;
    const std::int64_t us = us_past_hour;
    if (!started_) {
      started_ = true;
      last_us_ = us;
    }
    std::int64_t hours = hours_;
    const std::int64_t delta = us - last_us_;
    if (delta < -kHourUs / 2) {
      hours = ++hours_;  // wrapped past the top of the hour
      last_us_ = us;
    } else if (delta > kHourUs / 2) {
      hours = hours_ - 1;  // a straggler from before the last wrap; state unchanged
    } else if (delta > 0) {
      last_us_ = us;
    }
    return DeviceTime::from_ns((hours * kHourUs + us) * 1'000);
  }

 private:
  bool started_ = false;
  std::int64_t hours_ = 0;
  std::int64_t last_us_ = 0;
};

}  // namespace posed::drivers::velodyne
