#pragma once
// MeasurementSpan: the host-time interval a measurement was taken over, which is what the
// bundler and the pairer order, gate and pair by. A lidar scan spans its firings
// [start_stamp, end_stamp]; it is released by its END stamp because deskewing it needs the IMU
// up to its last firing. Anything else with a `stamp` (Image, a visible/thermal pair, a
// test's payload) is an instant: [stamp, stamp].
//
// A type with neither shape gets its own overload of MeasurementSpan::operator() (or a
// different functor passed as the template argument of MeasurementGate / StreamPairer).

#include <concepts>

#include "core/measurements.hpp"
#include "core/time.hpp"

namespace posed {

/// [begin, end] on the host clock [ns].
struct TimeSpan {
  /// first instant the measurement depends on [ns]
  HostTime begin;
  /// last instant, the one the IMU must cover before the measurement is released [ns]
  HostTime end;
};

struct MeasurementSpan {
  TimeSpan operator()(const LidarScan& scan) const { return {scan.start_stamp, scan.end_stamp}; }

  template <class T>
  requires requires(const T& m) {
    { m.stamp } -> std::convertible_to<HostTime>;
  }
  TimeSpan operator()(const T& m) const { return {m.stamp, m.stamp}; }
};

}  // namespace posed
