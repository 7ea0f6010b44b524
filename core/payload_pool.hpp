#pragma once
// Preallocated byte buffers for large payloads (scans, images). A driver acquires a buffer, fills
// it, and sends the Lease through a queue; whoever destroys the Lease returns the buffer. All
// memory is allocated at construction; acquire/release are lock-free (a tagged Treiber stack), so
// a lease may be released on any thread, e.g. by a queue dropping its oldest item.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace posed {

class PayloadPool {
 public:
  /// Owns one buffer until destroyed or moved from. Cheap to move, never copied.
  class Lease {
   public:
    Lease() = default;
    Lease(Lease&& o) noexcept : pool_(o.pool_), index_(o.index_) { o.pool_ = nullptr; }
    Lease& operator=(Lease&& o) noexcept {
      if (this != &o) {
        reset();
        pool_ = o.pool_;
        index_ = o.index_;
        o.pool_ = nullptr;
      }
      return *this;
    }
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    ~Lease() { reset(); }

    bool valid() const { return pool_ != nullptr; }
    explicit operator bool() const { return valid(); }
    /// The whole buffer (capacity bytes); the producer records how much it used.
    std::span<std::byte> bytes() const;
    template <class T>
    std::span<T> as() const {
      auto b = bytes();
      return {reinterpret_cast<T*>(b.data()), b.size() / sizeof(T)};
    }
    void reset();

   private:
    friend class PayloadPool;
    Lease(PayloadPool* pool, std::uint32_t index) : pool_(pool), index_(index) {}
    PayloadPool* pool_ = nullptr;
    std::uint32_t index_ = 0;
  };

  /// `buffer_count` buffers of `buffer_bytes` each, allocated now and never again.
  PayloadPool(std::size_t buffer_count, std::size_t buffer_bytes);
  PayloadPool(const PayloadPool&) = delete;
  PayloadPool& operator=(const PayloadPool&) = delete;

  /// A free buffer, or an invalid Lease when all are in use (the caller counts a drop).
  Lease acquire();

  std::size_t buffer_bytes() const { return buffer_bytes_; }
  std::size_t buffer_count() const { return next_.size(); }
  /// buffers currently leased out
  std::size_t in_use() const { return in_use_.load(std::memory_order_relaxed); }
  /// acquire() calls that found no free buffer
  std::uint64_t exhausted_count() const { return exhausted_.load(std::memory_order_relaxed); }

 private:
  void release(std::uint32_t index);

  static constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  /// Unmaps the storage (mapped by the constructor, see there).
  struct Unmap {
    std::size_t bytes = 0;
    void operator()(std::byte* p) const;
  };

  std::size_t buffer_bytes_;
  std::unique_ptr<std::byte[], Unmap> storage_;
  std::vector<std::atomic<std::uint32_t>> next_;
  /// low 32 bits: index of the top free buffer; high 32 bits: a tag against ABA
  std::atomic<std::uint64_t> head_;
  std::atomic<std::size_t> in_use_{0};
  std::atomic<std::uint64_t> exhausted_{0};
};

}  // namespace posed
