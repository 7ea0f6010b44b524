#include "core/payload_pool.hpp"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

#include "core/spsc_queue.hpp"

namespace posed {
namespace {

TEST(PayloadPool, HandsOutEveryBufferOnceThenReportsExhaustion) {
  PayloadPool pool(3, 64);
  std::vector<PayloadPool::Lease> leases;
  for (int i = 0; i < 3; ++i) {
    leases.push_back(pool.acquire());
    ASSERT_TRUE(leases.back().valid());
    EXPECT_EQ(leases.back().bytes().size(), 64u);
  }
  EXPECT_EQ(pool.in_use(), 3u);
  EXPECT_FALSE(pool.acquire().valid());
  EXPECT_EQ(pool.exhausted_count(), 1u);
  // Distinct buffers.
  EXPECT_NE(leases[0].bytes().data(), leases[1].bytes().data());
  EXPECT_NE(leases[1].bytes().data(), leases[2].bytes().data());
  leases.pop_back();
  EXPECT_EQ(pool.in_use(), 2u);
  EXPECT_TRUE(pool.acquire().valid());
}

TEST(PayloadPool, MovedLeaseReleasesOnce) {
  PayloadPool pool(1, 8);
  PayloadPool::Lease a = pool.acquire();
  PayloadPool::Lease b = std::move(a);
  EXPECT_FALSE(a.valid());  // NOLINT(bugprone-use-after-move): checking the moved-from state
  EXPECT_TRUE(b.valid());
  b.reset();
  EXPECT_EQ(pool.in_use(), 0u);
  EXPECT_TRUE(pool.acquire().valid());
}

TEST(PayloadPool, LeasesCrossThreadsThroughAQueue) {
  // The realistic pattern: a driver fills buffers, the core releases them on another thread.
  PayloadPool pool(8, sizeof(std::uint64_t));
  SpscQueue<PayloadPool::Lease> queue(4, DropPolicy::kDropOldest);
  constexpr std::uint64_t kItems = 20'000;
  std::uint64_t received = 0;
  std::uint64_t last = 0;
  bool ordered = true;
  std::thread consumer([&] {
    while (received + queue.counters().dropped_oldest < kItems) {
      if (auto lease = queue.pop()) {
        const std::uint64_t v = lease->as<std::uint64_t>()[0];
        if (v <= last && received > 0) ordered = false;
        last = v;
        ++received;
      }
    }
  });
  std::uint64_t produced = 0;
  while (produced < kItems) {
    PayloadPool::Lease lease = pool.acquire();
    if (!lease) {
      std::this_thread::yield();
      continue;
    }
    lease.as<std::uint64_t>()[0] = ++produced;
    queue.push(std::move(lease));
  }
  consumer.join();
  EXPECT_TRUE(ordered);
  EXPECT_EQ(received + queue.counters().dropped_oldest, kItems);
  EXPECT_EQ(pool.in_use(), queue.size());
}

// Pages of [data, data + bytes) that are resident.
std::size_t resident_pages(const std::byte* data, std::size_t bytes) {
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const std::size_t pages = (bytes + page - 1) / page;
  std::vector<unsigned char> in_core(pages);
  if (::mincore(const_cast<std::byte*>(data), bytes, in_core.data()) != 0) {
    ADD_FAILURE() << "mincore: " << std::strerror(errno);
    return 0;
  }
  std::size_t n = 0;
  for (unsigned char c : in_core) n += c & 1;
  return n;
}

// A --loop pass builds its pools again. When malloc served them, glibc's mmap threshold (raised
// by the first large free) put the next pass's pools on heap pages an earlier pass had made
// resident, and posed's memory grew by the pools' size over the first passes.
TEST(PayloadPool, UnwrittenBuffersAreNotResidentEvenWhereTheHeapWasUsedBefore) {
  constexpr std::size_t kBytes = 1 << 20, kCount = 8;
  // What a previous pass leaves: a large block freed (raising the threshold), then one of the
  // same size from the heap, written and freed, its pages kept by the allocator.
  for (int i = 0; i < 2; ++i) {
    void* block = std::malloc(2 * kBytes * kCount);
    ASSERT_NE(block, nullptr);
    std::memset(block, 1, 2 * kBytes * kCount);
    std::free(block);
  }
  PayloadPool pool(kCount, kBytes);
  PayloadPool::Lease lease = pool.acquire();
  ASSERT_TRUE(lease);
  std::memset(lease.bytes().data(), 1, kBytes);
  const std::byte* storage = lease.bytes().data();  // the first buffer starts the storage
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  EXPECT_EQ(resident_pages(storage, kBytes), kBytes / page);
  EXPECT_EQ(resident_pages(storage + kBytes, kBytes * (kCount - 1)), 0u)
      << "the seven buffers nobody wrote are resident";
}

}  // namespace
}  // namespace posed
