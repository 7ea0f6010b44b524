#include "core/spsc_queue.hpp"

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <thread>

namespace posed {
namespace {

using namespace std::chrono_literals;

TEST(SpscQueue, CapacityRoundsUpToPowerOfTwo) {
  SpscQueue<int> q(5, DropPolicy::kDropNewest);
  EXPECT_EQ(q.capacity(), 8u);
}

TEST(SpscQueue, FifoOrder) {
  SpscQueue<int> q(4, DropPolicy::kDropNewest);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(q.push(i), PushResult::kPushed);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(q.pop(), i);
  EXPECT_FALSE(q.pop().has_value());
  const auto c = q.counters();
  EXPECT_EQ(c.pushed, 4u);
  EXPECT_EQ(c.popped, 4u);
  EXPECT_EQ(c.high_water, 4u);
}

TEST(SpscQueue, DropNewestKeepsQueuedItems) {
  SpscQueue<int> q(2, DropPolicy::kDropNewest);
  EXPECT_EQ(q.push(1), PushResult::kPushed);
  EXPECT_EQ(q.push(2), PushResult::kPushed);
  EXPECT_EQ(q.push(3), PushResult::kRejectedFull);
  EXPECT_EQ(q.counters().rejected_newest, 1u);
  EXPECT_EQ(q.pop(), 1);
  EXPECT_EQ(q.pop(), 2);
  EXPECT_FALSE(q.pop().has_value());
}

TEST(SpscQueue, DropOldestKeepsNewestItems) {
  SpscQueue<int> q(2, DropPolicy::kDropOldest);
  EXPECT_EQ(q.push(1), PushResult::kPushed);
  EXPECT_EQ(q.push(2), PushResult::kPushed);
  EXPECT_EQ(q.push(3), PushResult::kPushedDropped);
  EXPECT_EQ(q.push(4), PushResult::kPushedDropped);
  EXPECT_EQ(q.counters().dropped_oldest, 2u);
  EXPECT_EQ(q.pop(), 3);
  EXPECT_EQ(q.pop(), 4);
  EXPECT_EQ(q.counters().dropped(), 2u);
}

TEST(SpscQueue, BlockTimesOutWhenNobodyConsumes) {
  SpscQueue<int, std::chrono::steady_clock> q(2, DropPolicy::kBlockWithTimeout, 20ms);
  q.push(1);
  q.push(2);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(q.push(3), PushResult::kRejectedTimeout);
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 20ms);
  EXPECT_EQ(q.counters().rejected_timeout, 1u);
}

TEST(SpscQueue, BlockSucceedsOnceTheConsumerMakesRoom) {
  SpscQueue<int> q(2, DropPolicy::kBlockWithTimeout, 5s);
  q.push(1);
  q.push(2);
  std::thread consumer([&] {
    std::this_thread::sleep_for(10ms);
    EXPECT_EQ(q.pop(), 1);
  });
  EXPECT_EQ(q.push(3), PushResult::kPushed);
  consumer.join();
  EXPECT_EQ(q.pop(), 2);
  EXPECT_EQ(q.pop(), 3);
}

TEST(SpscQueue, MoveOnlyItemsAreDestroyedWithTheQueue) {
  auto counter = std::make_shared<int>(0);
  {
    SpscQueue<std::shared_ptr<int>> q(4, DropPolicy::kDropOldest);
    q.push(counter);
    q.push(counter);
    EXPECT_EQ(counter.use_count(), 3);
  }
  EXPECT_EQ(counter.use_count(), 1);
}

struct Item64 {
  std::uint64_t sequence = 0;
  std::array<std::uint64_t, 7> payload{};
};
static_assert(sizeof(Item64) == 64);

// Every policy under two real threads: the consumer sees a strictly increasing sequence with
// intact payloads, and pushed = popped + dropped. Run under TSan by the sanitizer build.
class SpscStress : public ::testing::TestWithParam<DropPolicy> {};

TEST_P(SpscStress, TwoThreadsNoLossOrCorruption) {
  constexpr std::uint64_t kItems = 500'000;
  SpscQueue<Item64> q(64, GetParam(), 10s);
  std::uint64_t consumed = 0;
  bool intact = true;
  bool ordered = true;
  std::atomic<bool> producer_done{false};
  std::thread consumer([&] {
    std::uint64_t last = 0;
    Item64 item;
    for (;;) {
      if (q.try_pop(item)) {
        if (item.sequence <= last) ordered = false;
        for (auto v : item.payload) intact = intact && v == item.sequence * 3;
        last = item.sequence;
        ++consumed;
      } else if (producer_done.load(std::memory_order_acquire) && q.empty()) {
        break;
      }
    }
  });
  std::uint64_t rejected = 0;
  for (std::uint64_t i = 1; i <= kItems; ++i) {
    Item64 item;
    item.sequence = i;
    item.payload.fill(i * 3);
    const auto r = q.push(item);
    if (r == PushResult::kRejectedFull || r == PushResult::kRejectedTimeout) ++rejected;
  }
  producer_done.store(true, std::memory_order_release);
  consumer.join();
  const auto c = q.counters();
  EXPECT_TRUE(ordered);
  EXPECT_TRUE(intact);
  EXPECT_EQ(c.popped, consumed);
  EXPECT_EQ(c.pushed, kItems - rejected);
  EXPECT_EQ(c.pushed, c.popped + c.dropped_oldest);
  if (GetParam() == DropPolicy::kBlockWithTimeout) {
    EXPECT_EQ(consumed, kItems);  // blocking never loses an item while the consumer runs
  }
}

INSTANTIATE_TEST_SUITE_P(AllPolicies, SpscStress,
                         ::testing::Values(DropPolicy::kDropOldest, DropPolicy::kDropNewest,
                                           DropPolicy::kBlockWithTimeout),
                         [](const auto& param_info) {
                           return std::string(to_string(param_info.param));
                         });

}  // namespace
}  // namespace posed
