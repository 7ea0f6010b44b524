#include "drivers/recording/crc32.hpp"

#include <array>
#include <cstring>

namespace posed::drivers::recording {
namespace {

// tables[k][b]: the CRC of byte b followed by k zero bytes (slicing-by-8, Intel's method).
using Tables = std::array<std::array<std::uint32_t, 256>, 8>;

constexpr Tables make_tables() {
  Tables t{};
  for (std::uint32_t b = 0; b < 256; ++b) {
    std::uint32_t c = b;
    for (int i = 0; i < 8; ++i) c = (c & 1u) != 0 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][b] = c;
  }
  for (std::size_t k = 1; k < 8; ++k) {
    for (std::size_t b = 0; b < 256; ++b) t[k][b] = (t[k - 1][b] >> 8) ^ t[0][t[k - 1][b] & 0xFFu];
  }
  return t;
}

constexpr Tables kTables = make_tables();

}  // namespace

void Crc32::update(const void* data, std::size_t size_bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint32_t c = state_;
  // Little-endian hosts only (x86-64, ARM64): the 8-byte load below assumes it.
  while (size_bytes >= 8) {
    std::uint32_t lo = 0, hi = 0;
    std::memcpy(&lo, p, 4);
    std::memcpy(&hi, p + 4, 4);
    lo ^= c;
    c = kTables[7][lo & 0xFFu] ^ kTables[6][(lo >> 8) & 0xFFu] ^ kTables[5][(lo >> 16) & 0xFFu] ^
        kTables[4][lo >> 24] ^ kTables[3][hi & 0xFFu] ^ kTables[2][(hi >> 8) & 0xFFu] ^
        kTables[1][(hi >> 16) & 0xFFu] ^ kTables[0][hi >> 24];
    p += 8;
    size_bytes -= 8;
  }
  while (size_bytes-- > 0) c = (c >> 8) ^ kTables[0][(c ^ *p++) & 0xFFu];
  state_ = c;
}

void Crc32::update(std::span<const std::byte> bytes) { update(bytes.data(), bytes.size()); }

std::uint32_t crc32(std::span<const std::byte> bytes) {
  Crc32 c;
  c.update(bytes);
  return c.value();
}

}  // namespace posed::drivers::recording
