#pragma once
// A bounded lock-free queue from one producer thread to one consumer thread, with a named drop
// policy and counters (DESIGN.md, Data flow). No allocation after construction.
//
// Why cells with sequence numbers (Vyukov's bounded queue) rather than a plain two-index ring:
// drop-oldest needs the *producer* to discard the oldest item when full. With a plain ring that
// races with the consumer reading the same slot. Here a slot is claimed with a CAS on the read
// index before it is read, so the producer can claim-and-discard exactly like the consumer, and
// neither ever touches a slot the other owns.

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
        int spins = 0;
        while (WaitClock::now() < deadline) {
          if (try_emplace(item)) return PushResult::kPushed;
          if (++spins < 64) {
            std::this_thread::yield();
          } else {
            std::this_thread::sleep_for(std::chrono::microseconds(50));
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
  struct Cell {
    std::atomic<std::size_t> seq{0};
    std::optional<T> value;
  };

  // Counters have a single writer each, so a relaxed load+store is enough (no RMW on hot paths).
  static void bump(std::atomic<std::uint64_t>& c) {
    c.store(c.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }

  bool try_emplace(T& item) {
    const std::size_t pos = write_pos_.load(std::memory_order_relaxed);
    Cell& cell = cells_[pos & mask_];
    if (cell.seq.load(std::memory_order_acquire) != pos) return false;  // full or being read
    cell.value.emplace(std::move(item));
    cell.seq.store(pos + 1, std::memory_order_release);
    write_pos_.store(pos + 1, std::memory_order_release);
    bump(pushed_);
    const std::size_t depth = pos + 1 - read_pos_.load(std::memory_order_relaxed);
    if (depth > high_water_.load(std::memory_order_relaxed) && depth <= capacity_) {
      high_water_.store(depth, std::memory_order_relaxed);
    }
    return true;
  }

  // Claims the oldest cell (consumer, or producer discarding under drop-oldest).
  bool claim(T& out) {
    std::size_t pos = read_pos_.load(std::memory_order_relaxed);
    for (;;) {
      Cell& cell = cells_[pos & mask_];
      const std::size_t seq = cell.seq.load(std::memory_order_acquire);
      const auto diff = static_cast<std::ptrdiff_t>(seq - (pos + 1));
      if (diff == 0) {
        if (read_pos_.compare_exchange_weak(pos, pos + 1, std::memory_order_acq_rel,
                                            std::memory_order_relaxed)) {
          out = std::move(*cell.value);
          cell.value.reset();
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
  const std::chrono::nanoseconds block_timeout_;
  std::unique_ptr<Cell[]> cells_;

  alignas(kCacheLine) std::atomic<std::size_t> write_pos_{0};
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
