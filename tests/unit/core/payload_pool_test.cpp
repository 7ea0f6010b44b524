#include "core/payload_pool.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace posed
