#include "core/sync/counter_unwrapper.hpp"

namespace posed {
namespace {

/// floor(a / b) for b > 0, also for negative a.
std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

}  // namespace

CounterUnwrapper::CounterUnwrapper(std::uint64_t modulus, Duration tick)
    : modulus_(modulus), tick_(tick) {}

CounterUnwrapper CounterUnwrapper::with_bits(unsigned bits, Duration tick) {
  // Out-of-range widths become an unusable modulus (every sample counted invalid), not UB.
  const std::uint64_t modulus = (bits >= 1 && bits <= 62) ? (std::uint64_t{1} << bits) : 0;
  return CounterUnwrapper(modulus, tick);
}

void CounterUnwrapper::reset() {
  have_previous_ = false;
  previous_ticks_ = 0;
}

CounterUnwrapper::Result CounterUnwrapper::unwrap(std::uint64_t raw) {
  return unwrap(raw, Duration::from_ns(0));
}

CounterUnwrapper::Result CounterUnwrapper::unwrap(std::uint64_t raw, Duration host_elapsed) {
  Result r;
  if (modulus_ < 2 || modulus_ > (std::uint64_t{1} << 62) || tick_.ns <= 0 || raw >= modulus_) {
    ++invalid_;
    r.stamp = DeviceTime::from_ns(previous_ticks_ * tick_.ns);
    return r;
  }
  const auto m = static_cast<std::int64_t>(modulus_);
  const auto raw_ticks = static_cast<std::int64_t>(raw);
  if (!have_previous_) {
    have_previous_ = true;
    previous_ticks_ = raw_ticks;
    newest_period_ = 0;
    r.valid = true;
    r.stamp = DeviceTime::from_ns(raw_ticks * tick_.ns);
    return r;
  }
  const std::int64_t expected = previous_ticks_ + host_elapsed.ns / tick_.ns;
  std::int64_t candidate = floor_div(expected, m) * m + raw_ticks;
  // The nearest of the three periods around the expected value.
  if (candidate - expected > m / 2) candidate -= m;
  if (expected - candidate > m / 2) candidate += m;
  // Count each period once: a straggler from before a wrap followed by newer samples must not
  // count the same wrap twice.
  const std::int64_t period_now = floor_div(candidate, m);
  if (period_now > newest_period_) {
    r.wrapped = true;
    wraps_ += static_cast<std::uint64_t>(period_now - newest_period_);
    newest_period_ = period_now;
  }
  previous_ticks_ = candidate;
  r.valid = true;
  r.stamp = DeviceTime::from_ns(candidate * tick_.ns);
  return r;
}

}  // namespace posed
