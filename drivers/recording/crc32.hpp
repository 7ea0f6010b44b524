#pragma once
// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, init and final XOR 0xFFFFFFFF): the
// checksum MCAP uses for chunks, the data section and the summary (mcap.dev spec, "Chunk",
// "Data End", "Footer"); identical to zlib's crc32(). Carry-less multiplication (PCLMULQDQ) on
// x86-64 CPUs that have it, slicing-by-8 tables elsewhere and for the last bytes, so that
// checking a chunk costs far less than decompressing it.

#include <cstddef>
#include <cstdint>
#include <span>

namespace posed::drivers::recording {

/// Incremental CRC-32: feed bytes in any split, read value() at any point.
class Crc32 {
 public:
  void update(std::span<const std::byte> bytes);
  void update(const void* data, std::size_t size_bytes);
  /// the CRC of everything fed so far
  std::uint32_t value() const { return state_ ^ 0xFFFFFFFFu; }
  void reset() { state_ = 0xFFFFFFFFu; }

 private:
  std::uint32_t state_ = 0xFFFFFFFFu;
};

/// One-shot CRC-32 of `bytes`.
std::uint32_t crc32(std::span<const std::byte> bytes);

}  // namespace posed::drivers::recording
