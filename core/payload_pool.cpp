#include "core/payload_pool.hpp"

#include <sys/mman.h>

#include <new>

namespace posed {

namespace {
// Pages straight from the kernel, not from malloc: none is resident until a buffer is first
// written, so spare buffers (the lidar's cover the worst case, docs/faults.md) cost address
// space, not memory; and all are unmapped when the pool goes, so they are the kernel's again.
// malloc cannot promise either: once a freed block of this size has raised glibc's mmap threshold
// (it follows the largest freed mapping up to 32 MB), the next pool of a --loop pass came from a
// heap whose pages an earlier pass had made resident, and stayed there (docs/faults.md).
std::byte* map_pages(std::size_t bytes) {
  if (bytes == 0) return nullptr;
  void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  return static_cast<std::byte*>(p);
}

constexpr std::uint64_t pack(std::uint32_t index, std::uint32_t tag) {
  return (static_cast<std::uint64_t>(tag) << 32) | index;
}
constexpr std::uint32_t index_of(std::uint64_t head) {
  return static_cast<std::uint32_t>(head & 0xFFFFFFFFu);
}
constexpr std::uint32_t tag_of(std::uint64_t head) {
  return static_cast<std::uint32_t>(head >> 32);
}
}  // namespace

PayloadPool::PayloadPool(std::size_t buffer_count, std::size_t buffer_bytes)
    : buffer_bytes_(buffer_bytes),
      // A reused buffer holds its last payload: nobody may read what it did not write.
      storage_(map_pages(buffer_count * buffer_bytes), Unmap{buffer_count * buffer_bytes}),
      next_(buffer_count),
      head_(pack(buffer_count == 0 ? kNone : 0, 0)) {
  for (std::size_t i = 0; i < buffer_count; ++i) {
    next_[i].store(i + 1 < buffer_count ? static_cast<std::uint32_t>(i + 1) : kNone,
                   std::memory_order_relaxed);
  }
}

void PayloadPool::Unmap::operator()(std::byte* p) const {
  if (p != nullptr) ::munmap(p, bytes);
}

PayloadPool::Lease PayloadPool::acquire() {
  std::uint64_t head = head_.load(std::memory_order_acquire);
  for (;;) {
    const std::uint32_t index = index_of(head);
    if (index == kNone) {
      exhausted_.fetch_add(1, std::memory_order_relaxed);
      return {};
    }
    const std::uint32_t next = next_[index].load(std::memory_order_relaxed);
    if (head_.compare_exchange_weak(head, pack(next, tag_of(head) + 1), std::memory_order_acq_rel,
                                    std::memory_order_acquire)) {
      in_use_.fetch_add(1, std::memory_order_relaxed);
      return Lease(this, index);
    }
  }
}

void PayloadPool::release(std::uint32_t index) {
  std::uint64_t head = head_.load(std::memory_order_relaxed);
  for (;;) {
    next_[index].store(index_of(head), std::memory_order_relaxed);
    if (head_.compare_exchange_weak(head, pack(index, tag_of(head) + 1), std::memory_order_release,
                                    std::memory_order_relaxed)) {
      in_use_.fetch_sub(1, std::memory_order_relaxed);
      return;
    }
  }
}

std::span<std::byte> PayloadPool::Lease::bytes() const {
  if (!pool_) return {};
  return {pool_->storage_.get() + static_cast<std::size_t>(index_) * pool_->buffer_bytes_,
          pool_->buffer_bytes_};
}

void PayloadPool::Lease::reset() {
  if (pool_) {
    pool_->release(index_);
    pool_ = nullptr;
  }
}

}  // namespace posed
