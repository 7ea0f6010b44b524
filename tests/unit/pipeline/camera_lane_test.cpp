// The camera front end's lane (CameraLane): tasks run one after another in the order posted, on
// a thread that is not the poster's; drain() returns only once everything posted has run and its
// writes are visible; a full lane makes the poster wait instead of dropping; what is still posted
// when the lane is destroyed runs first; its heartbeat goes on while it waits for work and stops
// while a task hangs.

#include "daemon/pipeline/camera_lane.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <thread>
#include <vector>

namespace posed::pipeline {
namespace {

TEST(CameraLane, RunsTasksInOrderOffTheCallersThreadAndDrainsThem) {
  CameraLane lane(config::ThreadSection{}, 8);
  std::vector<int> order;  // written by the lane only, read after drain()
  std::thread::id ran_on;
  for (int i = 0; i < 1000; ++i) {
    lane.post([&order, &ran_on, i] {
      order.push_back(i);
      ran_on = std::this_thread::get_id();
    });
  }
  lane.drain();
  ASSERT_EQ(order.size(), 1000u);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(order[static_cast<std::size_t>(i)], i);
  EXPECT_NE(ran_on, std::this_thread::get_id());
  const CameraLaneCounters c = lane.counters();
  EXPECT_EQ(c.tasks, 1000u);
  EXPECT_GT(c.full_waits, 0u) << "8 places for 1000 tasks: the poster must have waited";
}

TEST(CameraLane, DrainWaitsForTheTaskThatIsRunning) {
  CameraLane lane(config::ThreadSection{}, 4);
  std::atomic<bool> started{false};
  int written = 0;
  lane.post([&] {
    started = true;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    written = 42;
  });
  while (!started) std::this_thread::yield();
  lane.drain();  // the task has been taken off the queue: drain must still wait for it
  EXPECT_EQ(written, 42);
}

TEST(CameraLane, WhatIsPostedRunsBeforeTheLaneEnds) {
  int ran = 0;
  {
    CameraLane lane(config::ThreadSection{}, 64);
    for (int i = 0; i < 50; ++i) {
      lane.post([&ran] {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        ++ran;
      });
    }
  }
  EXPECT_EQ(ran, 50);
}

TEST(CameraLane, BeatsWhileIdleAndNotWhileATaskHangs) {
  using namespace std::chrono_literals;
  Heartbeat beat("camera_frontend");
  CameraLane lane(config::ThreadSection{}, 8, &beat);
  const auto wait_for_beat_after = [&beat](std::int64_t ns) {
    for (int i = 0; i < 400 && beat.last().ns <= ns; ++i) std::this_thread::sleep_for(5ms);
    return beat.last().ns > ns;
  };
  ASSERT_TRUE(wait_for_beat_after(0)) << "the lane never beat";
  // Idle, it beats again within kStageWaitTimeout (50 ms); 2 s is the margin for a slow machine.
  EXPECT_TRUE(wait_for_beat_after(beat.last().ns)) << "no beat while idle";

  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<bool> started{false};
  lane.post([&started, released] {
    started = true;
    released.wait();
  });
  while (!started) std::this_thread::yield();
  const std::int64_t before = beat.last().ns;
  std::this_thread::sleep_for(300ms);  // six idle periods
  EXPECT_EQ(beat.last().ns, before) << "the lane beat while its task hung";
  release.set_value();
  lane.drain();
  EXPECT_TRUE(wait_for_beat_after(before)) << "no beat after the task ended";
}

}  // namespace
}  // namespace posed::pipeline
