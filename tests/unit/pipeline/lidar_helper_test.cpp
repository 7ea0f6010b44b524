// The scan match's helper threads (LidarHelper): every part of a job runs exactly once and its
// writes are visible when run() returns, job after job; the parts do run beside the caller (two
// parts that wait for each other finish); without helper threads the caller runs them in order.

#include "daemon/pipeline/lidar_helper.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <vector>

namespace posed::pipeline {
namespace {

TEST(LidarHelper, EveryPartRunsOnceAndWhatItWroteIsSeen) {
  for (const std::size_t threads : {1u, 3u}) {
    LidarHelper helper(config::ThreadSection{}, threads);
    std::vector<int> out(16, -1);  // plain ints: the join must make the writes visible
    std::vector<int> runs(16, 0);
    std::size_t expected_parts = 0;
    for (int job = 0; job < 2000; ++job) {
      const std::size_t parts = 1 + static_cast<std::size_t>(job) % 9;
      helper.run(parts, [&](std::size_t i) {
        out[i] = job * 100 + static_cast<int>(i);
        ++runs[i];
      });
      expected_parts += parts;
      for (std::size_t i = 0; i < parts; ++i) {
        ASSERT_EQ(out[i], job * 100 + static_cast<int>(i)) << "job " << job << " part " << i;
      }
    }
    int total = 0;
    for (const int r : runs) total += r;
    EXPECT_EQ(static_cast<std::size_t>(total), expected_parts) << threads << " helper(s)";
    const LidarHelperCounters c = helper.counters();
    EXPECT_EQ(c.jobs, 2000u);
    EXPECT_EQ(c.parts, expected_parts);
    EXPECT_LE(c.helper_parts, c.parts);
  }
}

TEST(LidarHelper, ThePartsRunBesideTheCaller) {
  LidarHelper helper(config::ThreadSection{}, 1);
  // Each part waits (up to 10 s) until both have started: run one after the other, the first
  // would wait in vain.
  std::mutex m;
  std::condition_variable cv;
  int started = 0;
  std::atomic<int> met{0};
  helper.run(2, [&](std::size_t) {
    std::unique_lock lock(m);
    ++started;
    cv.notify_all();
    if (cv.wait_for(lock, std::chrono::seconds(10), [&] { return started == 2; })) ++met;
  });
  EXPECT_EQ(met.load(), 2) << "the two parts did not run at the same time";
  EXPECT_EQ(helper.counters().helper_parts, 1u);
}

TEST(LidarHelper, WithoutHelperThreadsTheCallerRunsThePartsInOrder) {
  LidarHelper helper(config::ThreadSection{}, 0);
  std::vector<std::size_t> order;
  helper.run(5, [&](std::size_t i) { order.push_back(i); });
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(helper.counters().helper_parts, 0u);
}

}  // namespace
}  // namespace posed::pipeline
