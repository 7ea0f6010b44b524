#pragma once
// StampedRing<T>: a fixed-capacity ring of items kept in strictly increasing `.stamp` order,
// with binary search by stamp. The storage is allocated once at construction; push, pop and
// search never allocate. Shared by ImuBuffer and PoseHistory, which differ only in what they
// do with the items.
//
// The ring itself enforces the order (an item not newer than the newest is refused, and the
// caller counts it): keeping the order is what makes the binary search valid, and refusing
// rather than inserting is the policy both users want (see ImuBuffer for why).

#include <cstddef>
#include <vector>

#include "core/time.hpp"

namespace posed {

template <class T>
class StampedRing {
 public:
  /// What push() did with the item.
  enum class Push : unsigned char {
    kAppended,           ///< stored as the newest
    kAppendedOverwrote,  ///< stored; the ring was full, so the oldest item was overwritten
    kRefusedDuplicate,   ///< same stamp as the newest: not stored
    kRefusedOutOfOrder,  ///< older than the newest: not stored
    kRefusedNoCapacity   ///< capacity 0: nothing can be stored
  };

  /// `capacity` slots, allocated now and never again.
  explicit StampedRing(std::size_t capacity) : slots_(capacity) {}

  Push push(const T& item) {
    if (slots_.empty()) return Push::kRefusedNoCapacity;
    if (size_ > 0) {
      const HostTime newest = back().stamp;
      if (item.stamp == newest) return Push::kRefusedDuplicate;
      if (item.stamp < newest) return Push::kRefusedOutOfOrder;
    }
    if (size_ == slots_.size()) {
      slots_[head_] = item;
      head_ = wrap(head_ + 1);
      return Push::kAppendedOverwrote;
    }
    slots_[wrap(head_ + size_)] = item;
    ++size_;
    return Push::kAppended;
  }

  /// Removes the `n` oldest items (all of them when n >= size()).
  void pop_front(std::size_t n) {
    if (n >= size_) {
      clear();
      return;
    }
    head_ = wrap(head_ + n);
    size_ -= n;
  }

  void clear() {
    head_ = 0;
    size_ = 0;
  }

  /// Index of the first item with stamp >= t (size() when there is none). O(log n).
  std::size_t lower_bound(HostTime t) const {
    std::size_t lo = 0;
    std::size_t hi = size_;
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if ((*this)[mid].stamp < t) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return lo;
  }

  /// Index of the first item with stamp > t (size() when there is none). O(log n).
  std::size_t upper_bound(HostTime t) const {
    std::size_t lo = 0;
    std::size_t hi = size_;
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if ((*this)[mid].stamp <= t) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return lo;
  }

  /// The i-th oldest item; i < size().
  const T& operator[](std::size_t i) const { return slots_[wrap(head_ + i)]; }
  const T& front() const { return (*this)[0]; }
  const T& back() const { return (*this)[size_ - 1]; }

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  std::size_t capacity() const { return slots_.size(); }

 private:
  std::size_t wrap(std::size_t i) const { return i >= slots_.size() ? i - slots_.size() : i; }

  std::vector<T> slots_;
  /// slot of the oldest item
  std::size_t head_ = 0;
  std::size_t size_ = 0;
};

}  // namespace posed
