// ImuFailover: when the D435i's IMU stands in for the A9 and when the A9 takes over again.

#include "daemon/pipeline/imu_failover.hpp"

#include <gtest/gtest.h>

namespace posed::pipeline {
namespace {

HostTime ms(std::int64_t v) { return HostTime::from_ns(v * 1'000'000); }

TEST(ImuFailover, TheBackupStandsInOnlyWhileTheA9IsSilentAndNeverGoesBackInTime) {
  ImuFailover f(Duration::from_ms(50));
  // Both streaming: the A9's samples are used, the D435i's are not.
  for (int t = 0; t < 100; t += 5) {
    EXPECT_TRUE(f.take_primary(ms(t)));
    EXPECT_FALSE(f.take_backup(ms(t + 2)));
  }
  EXPECT_EQ(f.in_use(), ImuInUse::kA9);
  // The A9's last sample at 95 ms; the D435i's after 145 ms stand in for it.
  EXPECT_FALSE(f.take_backup(ms(140)));
  EXPECT_FALSE(f.switched());
  EXPECT_TRUE(f.take_backup(ms(146)));
  EXPECT_TRUE(f.switched());
  EXPECT_EQ(f.in_use(), ImuInUse::kBackup);
  EXPECT_EQ(f.switched_at(), ms(146));
  EXPECT_TRUE(f.take_backup(ms(151)));
  EXPECT_FALSE(f.switched());
  // The A9 back: a sample older than the last one used is skipped, the next newer one is used.
  EXPECT_FALSE(f.take_primary(ms(150)));
  EXPECT_EQ(f.in_use(), ImuInUse::kBackup);
  EXPECT_TRUE(f.take_primary(ms(155)));
  EXPECT_TRUE(f.switched());
  EXPECT_EQ(f.in_use(), ImuInUse::kA9);
  EXPECT_FALSE(f.take_backup(ms(157)));
  EXPECT_EQ(f.failovers(), 1u);
  EXPECT_EQ(f.backup_used(), 2u);
}

TEST(ImuFailover, AnA9NeverHeardIsSilentFromTheBackupsFirstSample) {
  ImuFailover f(Duration::from_ms(50));
  EXPECT_FALSE(f.take_backup(ms(1000)));
  EXPECT_FALSE(f.take_backup(ms(1050)));
  EXPECT_TRUE(f.take_backup(ms(1055)));
  EXPECT_EQ(f.in_use(), ImuInUse::kBackup);
  // An instance that only learns the A9's newest stamp (the live odometry's) decides alike.
  ImuFailover live(Duration::from_ms(50));
  live.saw_primary(ms(2000));
  EXPECT_FALSE(live.take_backup(ms(2040)));
  EXPECT_TRUE(live.take_backup(ms(2060)));
  live.saw_primary(ms(2070));
  EXPECT_FALSE(live.take_backup(ms(2075)));
}

}  // namespace
}  // namespace posed::pipeline
