// RealsenseImuCombiner: the D435i's accel (250 Hz) and gyro (200 Hz) readings into one sample per
// gyro reading, accel interpolated to its stamp, in the IMU frame, moved to the IMU's origin.

#include "drivers/camera/realsense_imu_combiner.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace posed::drivers::camera {
namespace {

D4xxMotionSample reading(MotionKind kind, std::int64_t t_ns, Eigen::Vector3d xyz) {
  D4xxMotionSample s;
  s.kind = kind;
  s.device_stamp = DeviceTime::from_ns(t_ns);
  s.xyz_depth = xyz;
  return s;
}

constexpr std::int64_t kMs = 1'000'000;

TEST(RealsenseImuCombiner, InterpolatesTheAccelToEachGyroStampOnceTheNextAccelArrives) {
  RealsenseImuCombiner c({});
  std::vector<RealsenseImuSample> out;
  const HostTime arrival = HostTime::from_ns(5);
  c.add(reading(MotionKind::kAccel, 0, {0, 0, 10}), arrival, out);
  c.add(reading(MotionKind::kGyro, 1 * kMs, {0.1, 0.2, 0.3}), arrival, out);
  c.add(reading(MotionKind::kGyro, 3 * kMs, {0.1, 0.2, 0.3}), arrival, out);
  EXPECT_TRUE(out.empty()) << "a gyro reading waits for the accel after it";
  EXPECT_EQ(c.pending(), 2u);
  c.add(reading(MotionKind::kAccel, 4 * kMs, {0, 0, 14}), arrival, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].device_stamp.ns, 1 * kMs);
  EXPECT_EQ(out[0].arrival, arrival);
  EXPECT_NEAR(out[0].specific_force_mps2.z(), 11.0, 1e-12);
  EXPECT_NEAR(out[1].specific_force_mps2.z(), 13.0, 1e-12);
  EXPECT_NEAR(out[1].angular_velocity_radps.y(), 0.2, 1e-12);
  EXPECT_EQ(c.counters().combined, 2u);
  EXPECT_EQ(c.counters().held, 0u);
}

TEST(RealsenseImuCombiner, TurnsIntoTheImuFrameAndRemovesTheLeverArmsCentripetalForce) {
  // Spinning about the IMU frame's z at 1 rad/s, the D435i's IMU 1 m out on x feels 1 m/s^2
  // towards the axis; the A9 at the origin feels none. The D435i's axes here: depth frame
  // (x right, y down, z forward) mounted looking along the IMU's x, as the rig's camera is.
  RealsenseImuMounting m;
  m.R_imu_depth << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  m.p_imu_rsimu_m = {1, 0, 0};
  RealsenseImuCombiner c(m);
  const Eigen::Matrix3d R_depth_imu = m.R_imu_depth.transpose();
  const Eigen::Vector3d w_imu(0, 0, 1), f_at_rsimu_imu(-1, 0, 9.81);
  std::vector<RealsenseImuSample> out;
  for (int k = 0; k < 50; ++k) {
    const std::int64_t t = k * 4 * kMs;
    c.add(reading(MotionKind::kAccel, t, R_depth_imu * f_at_rsimu_imu), {}, out);
    c.add(reading(MotionKind::kGyro, t + kMs, R_depth_imu * w_imu), {}, out);
  }
  ASSERT_GT(out.size(), 40u);
  for (const auto& s : out) {
    EXPECT_LT((s.angular_velocity_radps - w_imu).norm(), 1e-12);
    EXPECT_LT((s.specific_force_mps2 - Eigen::Vector3d(0, 0, 9.81)).norm(), 1e-9);
  }
}

TEST(RealsenseImuCombiner, AStalledAccelStreamHoldsItsLastReadingAndNoneDropsTheGyro) {
  RealsenseImuCombiner c({});
  std::vector<RealsenseImuSample> out;
  for (int k = 0; k < 10; ++k) c.add(reading(MotionKind::kGyro, k * 5 * kMs, {0, 0, 1}), {}, out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(c.counters().no_accel, 10u - RealsenseImuCombiner::kMaxPending);
  c.add(reading(MotionKind::kAccel, 46 * kMs, {0, 0, 9}), {}, out);
  EXPECT_EQ(out.size(), RealsenseImuCombiner::kMaxPending) << "every waiting reading, held";
  out.clear();
  for (int k = 10; k < 20; ++k) c.add(reading(MotionKind::kGyro, k * 5 * kMs, {0, 0, 1}), {}, out);
  ASSERT_EQ(out.size(), 10u - RealsenseImuCombiner::kMaxPending);
  EXPECT_NEAR(out[0].specific_force_mps2.z(), 9.0, 1e-12);
  EXPECT_GE(c.counters().held, out.size());
  // A reading not newer than its stream's last is dropped, counted.
  c.add(reading(MotionKind::kGyro, 3 * kMs, {0, 0, 1}), {}, out);
  c.add(reading(MotionKind::kAccel, 46 * kMs, {0, 0, 9}), {}, out);
  EXPECT_EQ(c.counters().out_of_order, 2u);
}

}  // namespace
}  // namespace posed::drivers::camera
