#pragma once
// The voxel map's index: a voxel's 63-bit key to its slot. Scan-to-map matching looks up several
// voxels for each of ~8000 queries per scan, and std::unordered_map spent most of that in a
// division (the prime bucket count) and a pointer chase per bucket. This is open addressing with
// linear probing in one flat array: a multiplicative hash into a power-of-two table kept at most
// half full, and deletion by backward shift (no tombstones, so a long run does not slow the
// probes down). Keys are what VoxelMap::key_of makes: 63 bits, so all ones is free to mean empty.

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace posed::lidar {

class VoxelIndex {
 public:
  static constexpr std::uint64_t kEmptyKey = ~std::uint64_t{0};
  static constexpr std::uint32_t kNoSlot = ~std::uint32_t{0};

  explicit VoxelIndex(std::size_t expected_keys = 1u << 16) { reset(expected_keys); }

  /// The slot stored for `key`, or kNoSlot.
  std::uint32_t find(std::uint64_t key) const {
    for (std::size_t i = home(key);; i = (i + 1) & mask_) {
      const Entry& e = entries_[i];
      if (e.key == key) return e.slot;
      if (e.key == kEmptyKey) return kNoSlot;
    }
  }

  /// The slot stored for `key`, made (holding kNoSlot) if absent; second: whether it was made.
  std::pair<std::uint32_t*, bool> try_emplace(std::uint64_t key) {
    if (2 * (size_ + 1) > entries_.size()) grow();
    for (std::size_t i = home(key);; i = (i + 1) & mask_) {
      Entry& e = entries_[i];
      if (e.key == key) return {&e.slot, false};
      if (e.key == kEmptyKey) {
        e.key = key;
        e.slot = kNoSlot;
        ++size_;
        return {&e.slot, true};
      }
    }
  }

  /// Removes `key`; false if it was not there.
  bool erase(std::uint64_t key) {
    std::size_t hole = home(key);
    while (entries_[hole].key != key) {
      if (entries_[hole].key == kEmptyKey) return false;
      hole = (hole + 1) & mask_;
    }
    // Backward shift: every later entry of the run that may move into the hole does, so each key
    // stays reachable from its home without tombstones.
    for (std::size_t j = (hole + 1) & mask_; entries_[j].key != kEmptyKey; j = (j + 1) & mask_) {
      const std::size_t k = home(entries_[j].key);
      const bool stays = hole <= j ? (hole < k && k <= j) : (hole < k || k <= j);
      if (stays) continue;
      entries_[hole] = entries_[j];
      hole = j;
    }
    entries_[hole].key = kEmptyKey;
    --size_;
    return true;
  }

  std::size_t size() const { return size_; }
  void clear() { reset(entries_.size() / 2); }

 private:
  struct Entry {
    std::uint64_t key = kEmptyKey;
    std::uint32_t slot = kNoSlot;
  };

  std::size_t home(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }

  void reset(std::size_t expected_keys) {
    int bits = 4;
    while ((std::size_t{1} << bits) < 2 * expected_keys) ++bits;
    entries_.assign(std::size_t{1} << bits, Entry{});
    mask_ = entries_.size() - 1;
    shift_ = 64 - bits;
    size_ = 0;
  }

  void grow() {
    std::vector<Entry> old;
    old.swap(entries_);
    reset(old.size());  // twice the keys the old table could hold at half load
    for (const Entry& e : old) {
      if (e.key == kEmptyKey) continue;
      *try_emplace(e.key).first = e.slot;
    }
  }

  std::vector<Entry> entries_;
  std::size_t mask_ = 0;
  int shift_ = 64;
  std::size_t size_ = 0;
};

}  // namespace posed::lidar
