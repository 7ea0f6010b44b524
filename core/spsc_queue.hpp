#pragma once
// A bounded lock-free queue from one producer thread to one consumer thread, with a named drop
// policy and counters (DESIGN.md, Data flow). No allocation after construction.
//
// Why cells with sequence numbers (Vyukov's bounded queue) rather than a plain two-index ring:
// drop-oldest needs the *producer* to discard the oldest item when full. With a plain ring that
// races with the consumer reading the same slot. Here a slot is claimed with a CAS on the read
// index before it is read, so the producer can claim-and-discard exactly like the consumer, and
// neither ever touches a slot the other owns. Under the other policies only the consumer claims,
// and the same cells run as a plain ring (see try_emplace()), which moves half the cache lines.

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <optional>
#include <string_view>
#include <thread>
#include <type_traits>
#include <utility>

namespace posed::detail {
// 64 bytes on x86-64 and most ARM64 cores; a constant because
// std::hardware_destructive_interference_size is ABI-unstable (GCC warns).
inline constexpr std::size_t kCacheLine = 64;
}  // namespace posed::detail

namespace posed {

enum class DropPolicy : std::uint8_t {
  kDropOldest,        ///< full: discard the oldest queued item, keep the new one (live sensors)
  kDropNewest,        ///< full: refuse the new item (keep what is queued)
  kBlockWithTimeout,  ///< full: wait for space up to a timeout, then refuse (replay, recorder)
};

constexpr std::string_view to_string(DropPolicy p) {
  switch (p) {
    case DropPolicy::kDropOldest:
      return "drop_oldest";
    case DropPolicy::kDropNewest:
      return "drop_newest";
    case DropPolicy::kBlockWithTimeout:
      return "block";
  }
  return "unknown";
}

/// What happened to one push.
enum class PushResult : std::uint8_t {
  kPushed,          ///< queued
  kPushedDropped,   ///< queued, and the oldest item was discarded to make room
  kRejectedFull,    ///< not queued: full under drop-newest
  kRejectedTimeout  ///< not queued: still full when the block timeout expired
};

/// A snapshot of a queue's counters; each counter is written by one thread only.
struct QueueCounters {
  std::uint64_t pushed = 0;            ///< items accepted
  std::uint64_t popped = 0;            ///< items delivered to the consumer
  std::uint64_t dropped_oldest = 0;    ///< queued items discarded by drop-oldest
  std::uint64_t rejected_newest = 0;   ///< new items refused by drop-newest
  std::uint64_t rejected_timeout = 0;  ///< new items refused after the block timeout
  std::size_t high_water = 0;          ///< most items ever queued at once
  std::size_t capacity = 0;
  std::uint64_t dropped() const { return dropped_oldest + rejected_newest + rejected_timeout; }
};

using detail::kCacheLine;

template <class T, class WaitClock = std::chrono::steady_clock>
class SpscQueue {
 public:
  /// `capacity` is rounded up to a power of two. `block_timeout` applies to kBlockWithTimeout.
  SpscQueue(std::size_t capacity, DropPolicy policy,
            std::chrono::nanoseconds block_timeout = std::chrono::milliseconds(100))
      : capacity_(std::bit_ceil(capacity < 2 ? std::size_t{2} : capacity)),
        mask_(capacity_ - 1),
        policy_(policy),
        block_timeout_(block_timeout),
        cells_(std::make_unique<Cell[]>(capacity_)) {
    for (std::size_t i = 0; i < capacity_; ++i) cells_[i].seq.store(i, std::memory_order_relaxed);
  }
  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

  ~SpscQueue() {
    T discard;
    while (claim(discard)) {
    }
  }

  /// Producer side. Applies the drop policy when full.
  PushResult push(T item) {
    if (try_emplace(item)) return PushResult::kPushed;
    switch (policy_) {
      case DropPolicy::kDropNewest:
        bump(rejected_newest_);
        return PushResult::kRejectedFull;
      case DropPolicy::kDropOldest: {
        for (;;) {
          T discarded;
          if (claim(discarded)) bump(dropped_oldest_);
          if (try_emplace(item)) return PushResult::kPushedDropped;
          // The consumer holds the slot we need for the few instructions of a move: wait it out.
          std::this_thread::yield();
        }
      }
      case DropPolicy::kBlockWithTimeout: {
        const auto deadline = WaitClock::now() + block_timeout_;
        // A full queue means the consumer is busy for a while (a replay waiting on a scan's
        // registration): back off exponentially, 50 µs up to 2 ms, so a blocked producer costs a
        // few hundred wake-ups a second, not tens of thousands.
        int spins = 0;
        auto pause = std::chrono::microseconds(50);
        while (WaitClock::now() < deadline) {
          if (try_emplace(item)) return PushResult::kPushed;
          if (++spins < 64) {
            std::this_thread::yield();
          } else {
            std::this_thread::sleep_for(pause);
            pause = std::min(pause * 2, std::chrono::microseconds(2000));
          }
        }
        bump(rejected_timeout_);
        return PushResult::kRejectedTimeout;
      }
    }
    return PushResult::kRejectedFull;
  }

  /// Consumer side: the oldest item, or nullopt when empty.
  std::optional<T> pop() {
    T out;
    if (!claim(out)) return std::nullopt;
    bump(popped_);
    return out;
  }

  /// Consumer side, no optional: true and `out` filled when an item was there.
  bool try_pop(T& out) {
    if (!claim(out)) return false;
    bump(popped_);
    return true;
  }

  /// Approximate (exact when both sides are idle).
  std::size_t size() const {
    const auto w = write_pos_.load(std::memory_order_acquire);
    const auto r = read_pos_.load(std::memory_order_acquire);
    return w >= r ? static_cast<std::size_t>(w - r) : 0;
  }
  bool empty() const { return size() == 0; }
  std::size_t capacity() const { return capacity_; }
  DropPolicy policy() const { return policy_; }

  /// Safe from any thread.
  QueueCounters counters() const {
    QueueCounters c;
    c.pushed = pushed_.load(std::memory_order_relaxed);
    c.popped = popped_.load(std::memory_order_relaxed);
    c.dropped_oldest = dropped_oldest_.load(std::memory_order_relaxed);
    c.rejected_newest = rejected_newest_.load(std::memory_order_relaxed);
    c.rejected_timeout = rejected_timeout_.load(std::memory_order_relaxed);
    c.high_water = high_water_.load(std::memory_order_relaxed);
    c.capacity = capacity_;
    return c;
  }

 private:
  // A cell per cache line (at least): the producer filling cell i+1 never invalidates the line
  // the consumer is reading cell i from. The item lives in raw storage, not an optional, so a
  // consumer taking a trivially destructible item only reads the cell.
  struct alignas(kCacheLine) Cell {
    std::atomic<std::size_t> seq{0};
    alignas(T) std::byte storage[sizeof(T)];
    T* item() { return std::launder(reinterpret_cast<T*>(storage)); }
  };

  // Counters have a single writer each, so a relaxed load+store is enough (no RMW on hot paths).
  static void bump(std::atomic<std::uint64_t>& c) {
    c.store(c.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }

  // Two protocols share the cells. A cell holds an item for position `pos` once its seq is pos+1
  // (the producer's release store). Whether it is free again differs:
  //  - drop-oldest (the producer may claim too): Vyukov's — the claimer CASes read_pos_, then
  //    marks the cell free for the next lap with seq = pos + capacity;
  //  - otherwise (only the consumer claims): the classic ring — the consumer only publishes
  //    read_pos_, and the producer finds space from its cached copy of it. The consumer never
  //    writes a cell, so each item crosses between the cores once instead of twice.
  bool try_emplace(T& item) {
    const std::size_t pos = write_pos_.load(std::memory_order_relaxed);
    Cell& cell = cells_[pos & mask_];
    if (claimable_) {
      if (cell.seq.load(std::memory_order_acquire) != pos) return false;  // full or being read
    } else if (pos - cached_read_pos_ >= capacity_) {
      cached_read_pos_ = read_pos_.load(std::memory_order_acquire);
      if (pos - cached_read_pos_ >= capacity_) return false;  // full
    }
    ::new (static_cast<void*>(cell.storage)) T(std::move(item));
    cell.seq.store(pos + 1, std::memory_order_release);
    write_pos_.store(pos + 1, std::memory_order_release);
    bump(pushed_);
    // High water from a cached read position: reading the consumer's index on every push would
    // move its cache line between the cores each time. The cached value is never ahead of the
    // real one, so the estimate is an upper bound: only when it beats the mark is the real index
    // read, and the mark stays exact.
    const std::size_t high_water = high_water_.load(std::memory_order_relaxed);
    if (pos + 1 - cached_read_pos_ > high_water) {
      cached_read_pos_ = read_pos_.load(std::memory_order_acquire);
      const std::size_t depth = pos + 1 - cached_read_pos_;
      if (depth > high_water && depth <= capacity_) {
        high_water_.store(depth, std::memory_order_relaxed);
      }
    }
    return true;
  }

  // Takes the oldest item (the consumer, or the producer discarding under drop-oldest).
  bool claim(T& out) {
    if (!claimable_) {
      const std::size_t pos = read_pos_.load(std::memory_order_relaxed);
      Cell& cell = cells_[pos & mask_];
      if (cell.seq.load(std::memory_order_acquire) != pos + 1) return false;  // empty
      out = std::move(*cell.item());
      cell.item()->~T();
      read_pos_.store(pos + 1, std::memory_order_release);
      return true;
    }
    std::size_t pos = read_pos_.load(std::memory_order_relaxed);
    for (;;) {
      Cell& cell = cells_[pos & mask_];
      const std::size_t seq = cell.seq.load(std::memory_order_acquire);
      const auto diff = static_cast<std::ptrdiff_t>(seq - (pos + 1));
      if (diff == 0) {
        if (read_pos_.compare_exchange_weak(pos, pos + 1, std::memory_order_acq_rel,
                                            std::memory_order_relaxed)) {
          out = std::move(*cell.item());
          cell.item()->~T();
          cell.seq.store(pos + capacity_, std::memory_order_release);
          return true;
        }
        // pos was reloaded by the failed CAS; try again.
      } else if (diff < 0) {
        return false;  // empty
      } else {
        pos = read_pos_.load(std::memory_order_relaxed);
      }
    }
  }

  const std::size_t capacity_;
  const std::size_t mask_;
  const DropPolicy policy_;
  /// the producer may claim (drop-oldest): Vyukov's protocol, see try_emplace()
  const bool claimable_ = policy_ == DropPolicy::kDropOldest;
  const std::chrono::nanoseconds block_timeout_;
  std::unique_ptr<Cell[]> cells_;

  alignas(kCacheLine) std::atomic<std::size_t> write_pos_{0};
  std::size_t cached_read_pos_ = 0;  // producer only: read_pos_ as last seen, for high water
  alignas(kCacheLine) std::atomic<std::size_t> read_pos_{0};
  // Producer-written counters share a line; the consumer-written one has its own.
  alignas(kCacheLine) std::atomic<std::uint64_t> pushed_{0};
  std::atomic<std::uint64_t> dropped_oldest_{0};
  std::atomic<std::uint64_t> rejected_newest_{0};
  std::atomic<std::uint64_t> rejected_timeout_{0};
  std::atomic<std::size_t> high_water_{0};
  alignas(kCacheLine) std::atomic<std::uint64_t> popped_{0};
};

}  // namespace posed
