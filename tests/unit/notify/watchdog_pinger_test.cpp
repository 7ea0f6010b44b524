#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "daemon/notify/stage_watchdog.hpp"

namespace posed::notify {
// Named rather than anonymous: test binaries build as unity batches, where another file's
// helpers of the same name share the translation unit.
namespace watchdog_pinger_test {

const HostTime kStart = HostTime::from_ns(500'000'000'000);

Duration ms(std::int64_t v) { return Duration::from_ms(v); }

WatchdogHealth healthy() { return {}; }

WatchdogHealth stalled(const char* name, Duration silent, Duration deadline) {
  WatchdogHealth h;
  h.healthy = false;
  h.stalled.push_back({name, silent, deadline});
  return h;
}

TEST(WatchdogPinger, PingsAtHalfTheWatchdogTimeout) {
  WatchdogPinger pinger(Duration::from_s(5));
  ASSERT_EQ(pinger.ping_period(), ms(2500));

  EXPECT_EQ(pinger.poll(kStart, healthy(), "running"), "WATCHDOG=1") << "first poll pings";
  EXPECT_EQ(pinger.poll(kStart + ms(100), healthy(), "running"), std::nullopt);
  EXPECT_EQ(pinger.poll(kStart + ms(2499), healthy(), "running"), std::nullopt);
  EXPECT_EQ(pinger.poll(kStart + ms(2500), healthy(), "running"), "WATCHDOG=1");
  EXPECT_EQ(pinger.poll(kStart + ms(2600), healthy(), "running"), std::nullopt);
  // A late loop turn: the next period counts from the ping actually sent.
  EXPECT_EQ(pinger.poll(kStart + ms(5300), healthy(), "running"), "WATCHDOG=1");
  EXPECT_EQ(pinger.poll(kStart + ms(7700), healthy(), "running"), std::nullopt);
  EXPECT_EQ(pinger.poll(kStart + ms(7800), healthy(), "running"), "WATCHDOG=1");
  EXPECT_FALSE(pinger.reporting_stall());
}

TEST(WatchdogPinger, StallWithholdsPingAndSaysWhichStageForHowLong) {
  WatchdogPinger pinger(Duration::from_s(5));
  EXPECT_EQ(pinger.poll(kStart, healthy(), "running"), "WATCHDOG=1");

  const HostTime t1 = kStart + ms(3000);  // a ping would be due now
  EXPECT_EQ(pinger.poll(t1, stalled("fusion", ms(1500), ms(1000)), "running"),
            "STATUS=watchdog withheld: stage fusion silent 1.50 s (deadline 1.00 s)");
  EXPECT_TRUE(pinger.reporting_stall());
  // Within the refresh period: silence, and above all no WATCHDOG=1.
  EXPECT_EQ(pinger.poll(t1 + ms(500), stalled("fusion", ms(2000), ms(1000)), "running"),
            std::nullopt);
  EXPECT_EQ(pinger.poll(t1 + ms(1000), stalled("fusion", ms(2500), ms(1000)), "running"),
            "STATUS=watchdog withheld: stage fusion silent 2.50 s (deadline 1.00 s)");

  // Recovery: ping at once and put the routine status back.
  EXPECT_EQ(pinger.poll(t1 + ms(1100), healthy(), "aligned; imu 150 Hz"),
            "WATCHDOG=1\nSTATUS=aligned; imu 150 Hz");
  EXPECT_FALSE(pinger.reporting_stall());
  EXPECT_EQ(pinger.poll(t1 + ms(1200), healthy(), "aligned; imu 150 Hz"), std::nullopt);
  EXPECT_EQ(pinger.poll(t1 + ms(1100) + ms(2500), healthy(), "x"), "WATCHDOG=1");
}

TEST(WatchdogPinger, ShortStallStillPingsOnRecovery) {
  WatchdogPinger pinger(Duration::from_s(5));
  EXPECT_EQ(pinger.poll(kStart, healthy(), "ok"), "WATCHDOG=1");
  EXPECT_TRUE(pinger.poll(kStart + ms(100), stalled("imu_source", ms(300), ms(200)), "ok"));
  EXPECT_EQ(pinger.poll(kStart + ms(200), healthy(), ""),
            "WATCHDOG=1\nSTATUS=all stages healthy again");
}

TEST(WatchdogPinger, WithoutWatchdogNeverPingsButReportsStalls) {
  WatchdogPinger pinger(std::nullopt);
  EXPECT_EQ(pinger.ping_period(), std::nullopt);
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(pinger.poll(kStart + ms(100) * i, healthy(), "running"), std::nullopt);
  }
  const HostTime t = kStart + Duration::from_s(20);
  EXPECT_EQ(pinger.poll(t, stalled("publisher", ms(1200), ms(1000)), "running"),
            "STATUS=watchdog withheld: stage publisher silent 1.20 s (deadline 1.00 s)");
  EXPECT_EQ(pinger.poll(t + ms(100), healthy(), "running"), "STATUS=running");
}

// The whole rule end to end on a simulated clock: stages beat, the main loop turns every 100 ms,
// and a model of systemd restarts posed when no WATCHDOG=1 came for WatchdogSec.
TEST(WatchdogPinger, SystemdRestartsOnlyWhenAStageStalls) {
  const Duration watchdog_sec = Duration::from_s(5);
  const Duration deadline = Duration::from_s(1);
  const HostTime stall_begins = kStart + Duration::from_s(10);
  const HostTime stall_ends = kStart + Duration::from_s(20);

  StageWatchdog watchdog;
  const auto imu = watchdog.register_stage("imu_source", deadline, kStart);
  const auto fusion = watchdog.register_stage("fusion", deadline, kStart);
  WatchdogPinger pinger(watchdog_sec);

  std::optional<HostTime> last_ping;
  Duration longest_gap_before_stall{};
  std::optional<HostTime> systemd_would_kill_at;
  std::vector<std::string> stall_reports;
  for (HostTime now = kStart; now < kStart + Duration::from_s(30); now += ms(100)) {
    watchdog.heartbeat(imu, now);
    if (now < stall_begins || now >= stall_ends) watchdog.heartbeat(fusion, now);
    const auto message = pinger.poll(now, watchdog.check(now), "running");
    if (!message) continue;
    if (message->starts_with("STATUS=watchdog withheld")) stall_reports.push_back(*message);
    if (!message->starts_with("WATCHDOG=1")) continue;
    if (last_ping && now - *last_ping > watchdog_sec && !systemd_would_kill_at) {
      systemd_would_kill_at = *last_ping + watchdog_sec;
    }
    if (last_ping && now < stall_begins) {
      longest_gap_before_stall = std::max(longest_gap_before_stall, now - *last_ping);
    }
    last_ping = now;
  }

  // Healthy: pinged at half the timeout (plus at most one loop turn), never near the limit.
  EXPECT_LE(longest_gap_before_stall, watchdog_sec / 2 + ms(100));
  // Stalled: pings stop, and systemd fires within deadline + WatchdogSec of the stall.
  ASSERT_TRUE(systemd_would_kill_at.has_value()) << "the stall never starved the watchdog";
  EXPECT_GT(*systemd_would_kill_at, stall_begins);
  EXPECT_LE(*systemd_would_kill_at, stall_begins + deadline + watchdog_sec);
  // The stall was reported about once a second, always naming fusion and never imu_source.
  EXPECT_GE(stall_reports.size(), 8u);
  EXPECT_LE(stall_reports.size(), 10u);
  for (const auto& report : stall_reports) {
    EXPECT_NE(report.find("stage fusion silent"), std::string::npos) << report;
    EXPECT_EQ(report.find("imu_source"), std::string::npos) << report;
  }
}

}  // namespace watchdog_pinger_test
}  // namespace posed::notify
