#pragma once
// Cheap deterministic Gaussian noise for images (hundreds of thousands of draws per frame, where
// std::normal_distribution would cost more than the rendering): a table of N(0, 1) samples drawn
// once from a seeded mt19937_64, indexed by a xorshift64* stream. Not for statistics that need
// independence beyond 2^16 samples; sensor-noise texture on pixels is what it is for.

#include <array>
#include <cstdint>
#include <memory>
#include <random>

namespace posed::sim {

class FastNoise {
 public:
  explicit FastNoise(std::uint64_t seed) : table_(std::make_unique<std::array<float, kSize>>()) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    for (float& v : *table_) v = static_cast<float>(n(rng));
    state_ = seed | 1;
  }
  /// the next N(0, 1) value
  float normal() { return (*table_)[static_cast<std::size_t>(next() >> 48)]; }
  /// the next U[0, 1) value (24 bits)
  float uniform() { return static_cast<float>(next() >> 40) * (1.0f / 16777216.0f); }

 private:
  std::uint64_t next() {
    state_ ^= state_ >> 12;
    state_ ^= state_ << 25;
    state_ ^= state_ >> 27;
    return state_ * 0x2545F4914F6CDD1Dull;
  }

  static constexpr std::size_t kSize = 1u << 16;
  std::unique_ptr<std::array<float, kSize>> table_;
  std::uint64_t state_;
};

}  // namespace posed::sim
