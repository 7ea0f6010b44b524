#pragma once
// Turns a wrapping device counter (a 32-bit µs counter, µs past the hour) into a monotonic
// DeviceTime in ns. The period of the counter is known; what is not known from the raw value is
// how many periods have passed. Between consecutive samples we pick the unwrapped value nearest
// to the expected one: the previous value plus the host time elapsed since then. Guiding by host
// time (rather than assuming gaps shorter than half a period) resolves the hour of a VLP-32C stamp
// even after a long outage, and a device reset shows up as device time going backwards, which
// ClockSync detects; the unwrapper itself never guesses a reset.

#include <cstdint>

#include "core/time.hpp"

namespace posed {

class CounterUnwrapper {
 public:
  struct Result {
    /// the unwrapped stamp [ns]; unchanged from the previous one when !valid
    DeviceTime stamp;
    /// false when the raw value is outside [0, modulus): bad input, counted, not used
    bool valid = false;
    /// true when this sample crossed into a later period (a wrap or an hour rollover)
    bool wrapped = false;
  };

  /// A counter that wraps at `modulus` ticks of `tick` each, e.g. (3'600'000'000, 1 µs) for
  /// µs past the hour. A modulus < 2 or a tick <= 0 makes every sample invalid (counted).
  CounterUnwrapper(std::uint64_t modulus, Duration tick);

  /// An N-bit counter (1 <= bits <= 62), e.g. with_bits(32, Duration::from_us(1)).
  static CounterUnwrapper with_bits(unsigned bits, Duration tick);

  /// Unwraps assuming less than half a period passed since the previous sample.
  Result unwrap(std::uint64_t raw);
  /// Unwraps to the value nearest to previous + `host_elapsed` (host time since the previous
  /// sample); correct for any gap as long as the host estimate is within half a period.
  Result unwrap(std::uint64_t raw, Duration host_elapsed);

  /// Forgets the history: the next sample starts in period 0.
  void reset();

  std::uint64_t modulus() const { return modulus_; }
  Duration tick() const { return tick_; }
  /// forward period crossings so far [1]
  std::uint64_t wraps() const { return wraps_; }
  /// raw values outside [0, modulus) [1]
  std::uint64_t invalid() const { return invalid_; }

 private:
  std::uint64_t modulus_;
  Duration tick_;
  bool have_previous_ = false;
  /// previous unwrapped value [ticks]
  std::int64_t previous_ticks_ = 0;
  /// the latest period any sample fell in [1]
  std::int64_t newest_period_ = 0;
  std::uint64_t wraps_ = 0;
  std::uint64_t invalid_ = 0;
};

}  // namespace posed
