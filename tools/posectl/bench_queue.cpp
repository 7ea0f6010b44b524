// posectl bench queue: throughput of 64-byte items between two threads, and cross-thread latency
// (push on one thread -> pop on the other) at a paced rate, where queueing delay does not dominate.

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include "core/spsc_queue.hpp"
#include "tools/posectl/bench.hpp"

namespace posed::posectl {
namespace {

using Clock = std::chrono::steady_clock;

struct Item64 {
  std::int64_t sent_ns = 0;
  std::array<std::uint64_t, 7> payload{};
};
static_assert(sizeof(Item64) == 64);

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

double throughput_items_per_s(std::uint64_t items) {
  SpscQueue<Item64> q(1024, DropPolicy::kBlockWithTimeout, std::chrono::seconds(5));
  std::atomic<bool> start{false};
  std::uint64_t checksum = 0;
  std::thread consumer([&] {
    while (!start.load(std::memory_order_acquire)) {
    }
    Item64 item;
    for (std::uint64_t n = 0; n < items;) {
      if (q.try_pop(item)) {
        checksum += item.payload[0];
        ++n;
      }
    }
  });
  const auto t0 = Clock::now();
  start.store(true, std::memory_order_release);
  Item64 item;
  for (std::uint64_t i = 0; i < items; ++i) {
    item.payload[0] = i;
    q.push(item);
  }
  consumer.join();
  const double s = std::chrono::duration<double>(Clock::now() - t0).count();
  if (checksum != items * (items - 1) / 2) return -1.0;  // a lost or corrupted item
  return static_cast<double>(items) / s;
}

}  // namespace

int bench_queue() {
  constexpr std::uint64_t kItems = 20'000'000;
  std::vector<double> rates;
  for (int run = 0; run < 3; ++run) rates.push_back(throughput_items_per_s(kItems));
  if (*std::min_element(rates.begin(), rates.end()) < 0) {
    report("queue", "error_lost_items", 1, "count");
    return 1;
  }
  std::sort(rates.begin(), rates.end());
  report("queue", "throughput_64B_median", rates[1] / 1e6, "Mitems/s");
  report("queue", "throughput_64B_best", rates[2] / 1e6, "Mitems/s");

  // Latency: one item every 20 µs (50 kHz, well above any sensor) so each pop measures transfer.
  constexpr int kSamples = 100'000;
  SpscQueue<Item64> q(1024, DropPolicy::kDropNewest);
  std::vector<std::int64_t> latency_ns;
  latency_ns.reserve(kSamples);
  std::thread consumer([&] {
    Item64 item;
    while (static_cast<int>(latency_ns.size()) < kSamples) {
      if (q.try_pop(item)) latency_ns.push_back(now_ns() - item.sent_ns);
    }
  });
  for (int i = 0; i < kSamples; ++i) {
    const std::int64_t due = now_ns() + 20'000;
    Item64 item;
    item.sent_ns = now_ns();
    q.push(item);
    while (now_ns() < due) {
    }
  }
  consumer.join();
  std::sort(latency_ns.begin(), latency_ns.end());
  const auto pct = [&](double p) {
    return static_cast<double>(latency_ns[static_cast<std::size_t>(p * (kSamples - 1))]);
  };
  report("queue", "latency_p50", pct(0.50), "ns");
  report("queue", "latency_p99", pct(0.99), "ns");
  report("queue", "latency_max", static_cast<double>(latency_ns.back()), "ns");
  return 0;
}

}  // namespace posed::posectl
