#pragma once
// Time in posed: integer nanoseconds, one distinct type per clock (DESIGN.md, Time).
// A DeviceTime cannot be compared with a HostTime by accident: mapping one onto the other is
// ClockSync's job, and converting to wall time happens only when a DDS message is stamped.

#include <atomic>
#include <compare>
#include <cstdint>

namespace posed {

/// A span of time [ns]. Signed: differences between stamps can be negative.
struct Duration {
  std::int64_t ns = 0;

  static constexpr Duration from_ns(std::int64_t v) { return Duration{v}; }
  static constexpr Duration from_us(std::int64_t v) { return Duration{v * 1'000}; }
  static constexpr Duration from_ms(std::int64_t v) { return Duration{v * 1'000'000}; }
  static constexpr Duration from_s(std::int64_t v) { return Duration{v * 1'000'000'000}; }
  /// Rounds to the nearest nanosecond; for configuration values, never for stamps.
  static constexpr Duration from_seconds(double s) {
    return Duration{static_cast<std::int64_t>(s * 1e9 + (s >= 0 ? 0.5 : -0.5))};
  }
  /// For display and for maths in the estimator; never stored in queues or recordings.
  constexpr double seconds() const { return static_cast<double>(ns) * 1e-9; }

  constexpr auto operator<=>(const Duration&) const = default;
  constexpr Duration operator+(Duration o) const { return {ns + o.ns}; }
  constexpr Duration operator-(Duration o) const { return {ns - o.ns}; }
  constexpr Duration operator-() const { return {-ns}; }
  constexpr Duration operator*(std::int64_t k) const { return {ns * k}; }
  constexpr Duration operator/(std::int64_t k) const { return {ns / k}; }
  constexpr Duration& operator+=(Duration o) {
    ns += o.ns;
    return *this;
  }
  constexpr Duration& operator-=(Duration o) {
    ns -= o.ns;
    return *this;
  }
};

/// A point on one clock [ns since that clock's epoch]. `ClockTag` keeps clocks apart.
template <class ClockTag>
struct TimePoint {
  std::int64_t ns = 0;

  static constexpr TimePoint from_ns(std::int64_t v) { return TimePoint{v}; }
  constexpr double seconds() const { return static_cast<double>(ns) * 1e-9; }

  constexpr auto operator<=>(const TimePoint&) const = default;
  constexpr TimePoint operator+(Duration d) const { return {ns + d.ns}; }
  constexpr TimePoint operator-(Duration d) const { return {ns - d.ns}; }
  constexpr Duration operator-(TimePoint o) const { return {ns - o.ns}; }
  constexpr TimePoint& operator+=(Duration d) {
    ns += d.ns;
    return *this;
  }
};

/// A sensor's own clock (µs counter, µs past the hour, hardware frame clock), unwrapped to ns.
struct DeviceClock {};
/// The host's CLOCK_MONOTONIC: the one clock every measurement is put on.
struct HostClock {};
/// CLOCK_REALTIME (UNIX epoch): only for stamping DDS messages and naming recordings.
struct WallClock {};

using DeviceTime = TimePoint<DeviceClock>;
using HostTime = TimePoint<HostClock>;
using WallTime = TimePoint<WallClock>;

/// The offset between host monotonic and wall time, applied when a DDS message is stamped (core
/// never reads a clock). Fixed (a recording's), or followed: a live daemon's WallClockFollower
/// re-reads it and publishes it here when the wall clock steps (daemon/wall_clock_follower.hpp).
struct HostToWall {
  /// the offset, or the one at the start when followed
  Duration wall_minus_host;
  /// the followed offset [ns], when set (owned by the follower, which outlives every copy)
  const std::atomic<std::int64_t>* followed_ns = nullptr;

  Duration current() const {
    return followed_ns ? Duration{followed_ns->load(std::memory_order_relaxed)} : wall_minus_host;
  }
  WallTime operator()(HostTime t) const { return WallTime{t.ns + current().ns}; }
  /// The host time a stamp was made from (the inverse, with the offset of now).
  HostTime to_host(WallTime t) const { return HostTime{t.ns - current().ns}; }
};

}  // namespace posed
