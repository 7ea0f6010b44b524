#include "tools/faults/fault_text.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace posed::faults {

namespace {

bool parse_seconds(std::string_view text, double& out) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), out);
  return r.ec == std::errc{} && r.ptr == text.data() + text.size() && std::isfinite(out);
}

}  // namespace

bool parse_fault_text(std::string_view text, std::string_view form, std::string_view& kind,
                      FaultWindow& window, std::string& error) {
  const auto at = text.find('@');
  const auto plus = text.find('+', at == std::string_view::npos ? 0 : at);
  if (at == std::string_view::npos || plus == std::string_view::npos) {
    error = "fault '" + std::string(text) + "': expected " + std::string(form);
    return false;
  }
  kind = text.substr(0, at);
  if (!parse_seconds(text.substr(at + 1, plus - at - 1), window.start_s) || window.start_s < 0 ||
      !parse_seconds(text.substr(plus + 1), window.duration_s) || window.duration_s <= 0) {
    error = "fault '" + std::string(text) +
            "': start and duration must be seconds, start >= 0 and duration > 0";
    return false;
  }
  return true;
}

std::string window_text(const FaultWindow& window) {
  char text[64];
  std::snprintf(text, sizeof text, "@%g+%g", window.start_s, window.duration_s);
  return text;
}

void flip_random_bits(std::span<std::byte> bytes, std::mt19937_64& random) {
  if (bytes.empty()) return;
  std::uniform_int_distribution<std::size_t> where(0, bytes.size() - 1);
  std::uniform_int_distribution<int> bit(0, 7);
  for (std::size_t k = 0; k < std::max<std::size_t>(1, bytes.size() / 64); ++k) {
    bytes[where(random)] ^= static_cast<std::byte>(1u << bit(random));
  }
}

}  // namespace posed::faults
