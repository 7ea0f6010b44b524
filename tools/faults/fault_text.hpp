#pragma once
// What `posectl sim --fault` and `posectl replay --fault` share: the KIND@START+DURATION text
// (a fault's window in seconds) and how a corrupted burst garbles bytes. Each tool keeps its own
// kinds and what they do.

#include <cstddef>
#include <random>
#include <span>
#include <string>
#include <string_view>

namespace posed::faults {

/// A fault's time window [s].
struct FaultWindow {
  double start_s = 0;
  double duration_s = 0;
};

/// Splits "KIND@START+DURATION" into the text before '@' and the window (start >= 0, duration >
/// 0, both finite). False with `error` naming the text and saying what was expected: `form`
/// ("KIND@START+DURATION (seconds), e.g. drop@5+2").
bool parse_fault_text(std::string_view text, std::string_view form, std::string_view& kind,
                      FaultWindow& window, std::string& error);

/// "@START+DURATION", as parse_fault_text reads it back.
std::string window_text(const FaultWindow& window);

/// Flips one random bit per 64 bytes (at least one): a burst of bit errors on a link. Draws the
/// byte then the bit from `random`, in that order, so a seed garbles the same way every run.
void flip_random_bits(std::span<std::byte> bytes, std::mt19937_64& random);

}  // namespace posed::faults
