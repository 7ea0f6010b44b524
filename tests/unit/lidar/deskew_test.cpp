// Deskew on a synthetic rotating scan: a sensor turning at 1 rad/s sweeps a wall over 0.1 s;
// undistorted with the motion, every point lands on the wall as seen from the scan's end.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/lidar/scan_motion.hpp"
#include "core/math/so3.hpp"

namespace posed::lidar {
namespace {

constexpr double kYawRate = 1.0;  // [rad/s]
constexpr double kSpeed = 5.0;    // forward [m/s]
constexpr double kScanSeconds = 0.1;

/// The lidar's pose at time t (world frame: start of the scan), turning and driving.
Eigen::Isometry3d pose_at(double t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3::exp(Eigen::Vector3d(0, 0, kYawRate * t));
  T.translation() = Eigen::Vector3d(kSpeed * t, 0, 0);
  return T;
}

/// A wall x = 10 m in the world, seen by one ring over a full turn.
std::vector<LidarPoint> scan_of_wall(std::vector<Eigen::Vector3d>& world_points) {
  std::vector<LidarPoint> points;
  for (int i = 0; i < 1800; ++i) {
    const double t = kScanSeconds * i / 1800.0;
    const Eigen::Isometry3d T = pose_at(t);
    const double az = 2 * std::numbers::pi * i / 1800.0 - std::numbers::pi;
    const Eigen::Vector3d dir_world =
        T.linear() * Eigen::Vector3d(std::cos(az), std::sin(az), 0.05);
    if (dir_world.x() <= 0.1) continue;  // facing away from the wall
    const double range = (10.0 - T.translation().x()) / dir_world.x();
    const Eigen::Vector3d p_world = T.translation() + range * dir_world;
    const Eigen::Vector3d p_sensor = T.inverse() * p_world;
    LidarPoint lp;
    lp.x = static_cast<float>(p_sensor.x());
    lp.y = static_cast<float>(p_sensor.y());
    lp.z = static_cast<float>(p_sensor.z());
    lp.offset_ns = static_cast<std::int32_t>(t * 1e9);
    lp.ring = 16;
    points.push_back(lp);
    world_points.push_back(p_world);
  }
  return points;
}

ScanMotion motion() {
  ScanMotion m;
  const Eigen::Isometry3d T_end_inv = pose_at(kScanSeconds).inverse();
  for (int k = 0; k <= 20; ++k) {
    const double t = kScanSeconds * k / 20.0;
    m.stamps.push_back(HostTime::from_ns(static_cast<std::int64_t>(t * 1e9)));
    m.T_end_t.push_back(T_end_inv * pose_at(t));
  }
  return m;
}

TEST(Deskew, MovesEveryPointIntoTheFrameAtTheScanEnd) {
  std::vector<Eigen::Vector3d> world;
  const std::vector<LidarPoint> raw = scan_of_wall(world);
  ASSERT_GT(raw.size(), 500u);
  std::vector<ScanPoint> out;
  deskew(raw, HostTime::from_ns(0), motion(), 1800, 0.5f, 100.0f, out);
  ASSERT_EQ(out.size(), raw.size());
  const Eigen::Isometry3d T_end = pose_at(kScanSeconds);
  double max_error = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    max_error = std::max(max_error, (T_end * out[i].p.cast<double>() - world[i]).norm());
  }
  // Interpolating 5 ms motion samples: sub-millimetre, plus float rounding at 10 m.
  EXPECT_LT(max_error, 0.002);

  // Without the motion the wall is smeared: the turn alone moves far points by decimetres.
  deskew(raw, HostTime::from_ns(0), ScanMotion{}, 1800, 0.5f, 100.0f, out);
  double max_skew = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    max_skew = std::max(max_skew, (T_end * out[i].p.cast<double>() - world[i]).norm());
  }
  EXPECT_GT(max_skew, 0.3);
}

TEST(Deskew, RangeLimitsAndNonFinitePointsAreDropped) {
  std::vector<LidarPoint> raw(4);
  raw[0].x = 0.2f;                                     // too close
  raw[1].x = 5.0f;                                     // kept
  raw[2].x = 500.0f;                                   // too far
  raw[3].x = std::numeric_limits<float>::quiet_NaN();  // garbage
  std::vector<ScanPoint> out;
  deskew(raw, HostTime::from_ns(0), ScanMotion{}, 1800, 0.5f, 100.0f, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FLOAT_EQ(out[0].range_m, 5.0f);
}

}  // namespace
}  // namespace posed::lidar
