#include "daemon/notify/stage_watchdog.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

namespace posed::notify {
namespace {

const HostTime kStart = HostTime::from_ns(1'000'000'000'000);  // an arbitrary boot-relative time

Duration ms(std::int64_t v) { return Duration::from_ms(v); }

TEST(StageWatchdog, AllStagesBeatingIsHealthy) {
  StageWatchdog watchdog;
  const auto imu = watchdog.register_stage("imu_source", ms(100), kStart);
  const auto fusion = watchdog.register_stage("fusion", ms(500), kStart);
  for (int step = 1; step <= 50; ++step) {
    const HostTime now = kStart + ms(50) * step;
    EXPECT_TRUE(watchdog.heartbeat(imu, now));
    if (step % 5 == 0) {
      EXPECT_TRUE(watchdog.heartbeat(fusion, now));
    }
    const WatchdogHealth health = watchdog.check(now + ms(10));
    EXPECT_TRUE(health.healthy) << "step " << step << ": " << health.describe();
    EXPECT_TRUE(health.stalled.empty());
    EXPECT_EQ(health.describe(), "");
  }
}

TEST(StageWatchdog, RegistrationCountsAsTheFirstBeat) {
  StageWatchdog watchdog;
  watchdog.register_stage("fusion", ms(1000), kStart);
  EXPECT_TRUE(watchdog.check(kStart + ms(1000)).healthy);
  EXPECT_FALSE(watchdog.check(kStart + ms(1001)).healthy);
}

TEST(StageWatchdog, StallIsNamedWithItsSilenceThenRecovers) {
  StageWatchdog watchdog;
  const auto imu = watchdog.register_stage("imu_source", ms(200), kStart);
  const auto fusion = watchdog.register_stage("fusion", ms(1000), kStart);
  const auto publisher = watchdog.register_stage("publisher", ms(1000), kStart);

  HostTime now = kStart + ms(900);
  watchdog.heartbeat(imu, now);
  watchdog.heartbeat(fusion, now - ms(400));  // fusion's last word, at kStart + 500 ms
  watchdog.heartbeat(publisher, now);
  EXPECT_TRUE(watchdog.check(now).healthy);

  // Exactly at its deadline the stage is still within it...
  now = kStart + ms(1500);
  watchdog.heartbeat(imu, now);
  watchdog.heartbeat(publisher, now);
  EXPECT_TRUE(watchdog.check(now).healthy);
  // ...one nanosecond later it is not.
  WatchdogHealth health = watchdog.check(now + Duration::from_ns(1));
  EXPECT_FALSE(health.healthy);
  ASSERT_EQ(health.stalled.size(), 1u);
  EXPECT_EQ(health.stalled[0].name, "fusion");
  EXPECT_EQ(health.stalled[0].silent_for, ms(1000) + Duration::from_ns(1));
  EXPECT_EQ(health.stalled[0].deadline, ms(1000));

  now = kStart + ms(2800);
  watchdog.heartbeat(imu, now);
  watchdog.heartbeat(publisher, now);
  health = watchdog.check(now);
  ASSERT_EQ(health.stalled.size(), 1u);
  EXPECT_EQ(health.stalled[0].silent_for, ms(2300));
  EXPECT_EQ(health.describe(), "watchdog withheld: stage fusion silent 2.30 s (deadline 1.00 s)");

  // Fusion comes back.
  now = kStart + ms(2900);
  watchdog.heartbeat(fusion, now);
  health = watchdog.check(now);
  EXPECT_TRUE(health.healthy) << health.describe();
  EXPECT_TRUE(health.stalled.empty());
}

TEST(StageWatchdog, EachStageHasItsOwnDeadline) {
  StageWatchdog watchdog;
  watchdog.register_stage("imu_source", ms(100), kStart);
  watchdog.register_stage("fusion", ms(1000), kStart);
  const WatchdogHealth health = watchdog.check(kStart + ms(150));
  ASSERT_EQ(health.stalled.size(), 1u);
  EXPECT_EQ(health.stalled[0].name, "imu_source");

  const WatchdogHealth both = watchdog.check(kStart + ms(1200));
  ASSERT_EQ(both.stalled.size(), 2u);
  EXPECT_EQ(both.stalled[0].name, "imu_source");
  EXPECT_EQ(both.stalled[1].name, "fusion");
  EXPECT_EQ(both.describe(),
            "watchdog withheld: stages imu_source silent 1.20 s (deadline 0.10 s), "
            "fusion silent 1.20 s (deadline 1.00 s)");
}

TEST(StageWatchdog, BeatStampedAfterTheCheckTimeIsHealthy) {
  StageWatchdog watchdog;
  const auto id = watchdog.register_stage("fusion", ms(100), kStart);
  watchdog.heartbeat(id, kStart + ms(500));
  EXPECT_TRUE(watchdog.check(kStart + ms(499)).healthy);
}

TEST(StageWatchdog, NoStagesIsHealthy) {
  const StageWatchdog watchdog;
  EXPECT_TRUE(watchdog.check(kStart).healthy);
  EXPECT_EQ(watchdog.stage_count(), 0u);
}

TEST(StageWatchdog, UnknownIdIsRefused) {
  StageWatchdog watchdog;
  EXPECT_FALSE(watchdog.heartbeat(0, kStart));
  const auto id = watchdog.register_stage("fusion", ms(100), kStart);
  EXPECT_TRUE(watchdog.heartbeat(id, kStart));
  EXPECT_FALSE(watchdog.heartbeat(id + 1, kStart));
}

TEST(StageWatchdog, WiringMistakesThrowWithTheStageName) {
  StageWatchdog watchdog(2);
  try {
    watchdog.register_stage("fusion", Duration{}, kStart);
    FAIL() << "a zero deadline was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fusion"), std::string::npos) << e.what();
  }
  watchdog.register_stage("a", ms(1), kStart);
  watchdog.register_stage("b", ms(1), kStart);
  try {
    watchdog.register_stage("recorder", ms(1), kStart);
    FAIL() << "a third stage fit into two slots";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("recorder"), std::string::npos) << e.what();
  }
  EXPECT_EQ(watchdog.stage_count(), 2u);
}

// Stage threads beat while another thread checks (run under POSED_TSAN to see races). Each
// thread's final beat is far in the future, so the last check must see every one of them.
TEST(StageWatchdog, ConcurrentHeartbeatsAndChecks) {
  StageWatchdog watchdog;
  constexpr int kThreads = 4;
  constexpr int kBeats = 20'000;
  std::vector<StageWatchdog::StageId> ids;
  for (int i = 0; i < kThreads; ++i) {
    ids.push_back(watchdog.register_stage("stage" + std::to_string(i), ms(1), kStart));
  }
  std::atomic<bool> done{false};
  std::thread checker([&] {
    while (!done.load()) (void)watchdog.check(kStart);
  });
  std::vector<std::thread> stages;
  for (int i = 0; i < kThreads; ++i) {
    stages.emplace_back([&, i] {
      for (int b = 1; b <= kBeats; ++b) {
        watchdog.heartbeat(ids[static_cast<std::size_t>(i)], kStart + Duration::from_us(b));
      }
    });
  }
  for (auto& t : stages) t.join();
  done.store(true);
  checker.join();
  const HostTime last = kStart + Duration::from_us(kBeats);
  EXPECT_TRUE(watchdog.check(last + ms(1)).healthy);
  EXPECT_EQ(watchdog.check(last + ms(1) + Duration::from_ns(1)).stalled.size(),
            static_cast<std::size_t>(kThreads));
}

}  // namespace
}  // namespace posed::notify
