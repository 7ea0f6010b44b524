// PointCloud2 -> LidarScan (drivers/recording/ros1_cloud_scan.hpp): velodyne_pointcloud's layout
// with point times either side of header.stamp, other field orders and types, clouds without
// ring or time fields, invalid points, and a pool that is full or too small.

#include "drivers/recording/ros1_cloud_scan.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "drivers/velodyne/calibration.hpp"
#include "tests/common/ros1_serialize.hpp"

namespace posed::testing {
namespace ros1_cloud_scan_test {

namespace ros1 = drivers::recording::ros1;
namespace ser = test::ros1;

struct P {
  float x, y, z, intensity;
  std::uint16_t ring;
  float time_s;
};

/// A cloud in velodyne_pointcloud's PointXYZIRT layout.
std::vector<std::byte> velodyne_cloud(const std::vector<P>& points, std::int64_t stamp_ns) {
  std::vector<std::byte> data(points.size() * ser::kVelodynePointStep);
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::byte* p = data.data() + i * ser::kVelodynePointStep;
    std::memcpy(p + 0, &points[i].x, 4);
    std::memcpy(p + 4, &points[i].y, 4);
    std::memcpy(p + 8, &points[i].z, 4);
    std::memcpy(p + 16, &points[i].intensity, 4);
    std::memcpy(p + 20, &points[i].ring, 2);
    std::memcpy(p + 24, &points[i].time_s, 4);
  }
  return ser::point_cloud2(1, stamp_ns, "velodyne", 1, static_cast<std::uint32_t>(points.size()),
                           ser::velodyne_fields(), ser::kVelodynePointStep, data);
}

/// The cloud views `bytes`, which must outlive it (a temporary does not).
ros1::PointCloud2 decode(const std::vector<std::byte>& bytes) {
  ros1::PointCloud2 cloud;
  EXPECT_EQ(ros1::decode_point_cloud2(bytes, cloud), ros1::Ros1Status::kOk);
  return cloud;
}

constexpr std::int64_t kStamp = 1'628'000'000'000'000'000;

TEST(CloudScan, VelodyneLayoutWithTimesBeforeTheStamp) {
  // Older velodyne_pointcloud stamps the cloud with its last packet: times are negative.
  const std::vector<P> points{
      {10, 0, 0, 5, 3, -0.099f}, {0, 10, 1, 7, 17, -0.05f}, {-10, 0, -1, 9, 30, 0.0f}};
  const auto bytes = velodyne_cloud(points, kStamp);
  PayloadPool pool(2, 100 * sizeof(LidarPoint));
  ros1::CloudScanDecoder decoder(pool, {});
  LidarScan scan;
  ros1::CloudScanInfo info;
  ASSERT_EQ(decoder.decode(decode(bytes), HostTime::from_ns(kStamp), scan, info),
            ros1::CloudScanStatus::kOk);
  EXPECT_TRUE(info.has_time);
  EXPECT_FALSE(info.derived_ring);
  ASSERT_EQ(scan.point_count, 3u);
  EXPECT_EQ(info.points_out, 3u);
  // The scan starts at the earliest point (float32 seconds: about 10 ns resolution here).
  EXPECT_NEAR(static_cast<double>(scan.start_stamp.ns - kStamp), -0.099e9, 100);
  EXPECT_NEAR(static_cast<double>(scan.end_stamp.ns - kStamp), 0.0, 100);
  const auto lp = scan.points.as<LidarPoint>();
  EXPECT_EQ(lp[0].offset_ns, 0);
  EXPECT_NEAR(lp[1].offset_ns, 49'000'000, 100);
  EXPECT_NEAR(lp[2].offset_ns, 99'000'000, 100);
  EXPECT_EQ(lp[1].ring, 17);
  EXPECT_EQ(lp[2].intensity, 9.f);
  EXPECT_EQ(lp[1].y, 10.f);
  // Each point's absolute time is start + offset = stamp + time.
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(static_cast<double>(scan.start_stamp.ns + lp[i].offset_ns - kStamp),
                points[i].time_s * 1e9, 100);
  }
  EXPECT_EQ(scan.sequence, 0u);
}

TEST(CloudScan, OtherFieldOrdersTypesAndExtraFieldsGiveTheSameScan) {
  // z, ring (uint8), t... a layout another driver might use: float64 x/y/z, uint8 intensity and
  // ring, float64 time, with an rgb field and padding in between.
  const std::vector<ser::Field> fields{
      {"rgb", 0, 7, 1}, {"time", 4, 8, 1},  {"z", 12, 8, 1},        {"y", 20, 8, 1},
      {"x", 28, 8, 1},  {"ring", 36, 2, 1}, {"intensity", 37, 2, 1}};
  const std::uint32_t step = 40;
  std::vector<std::byte> data(2 * step);
  const auto put = [&](std::size_t i, double x, double y, double z, std::uint8_t ring,
                       std::uint8_t intensity, double t) {
    std::byte* p = data.data() + i * step;
    std::memcpy(p + 4, &t, 8);
    std::memcpy(p + 12, &z, 8);
    std::memcpy(p + 20, &y, 8);
    std::memcpy(p + 28, &x, 8);
    std::memcpy(p + 36, &ring, 1);
    std::memcpy(p + 37, &intensity, 1);
  };
  put(0, 5, 1, 0.5, 4, 200, 0.01);
  put(1, -5, 2, 0.25, 9, 100, 0.06);
  const auto bytes = ser::point_cloud2(2, kStamp, "lidar", 1, 2, fields, step, data);
  PayloadPool pool(1, 16 * sizeof(LidarPoint));
  ros1::CloudScanDecoder decoder(pool, {});
  LidarScan scan;
  ros1::CloudScanInfo info;
  ASSERT_EQ(decoder.decode(decode(bytes), HostTime::from_ns(kStamp), scan, info),
            ros1::CloudScanStatus::kOk);
  ASSERT_EQ(scan.point_count, 2u);
  const auto lp = scan.points.as<LidarPoint>();
  EXPECT_EQ(lp[0].x, 5.f);
  EXPECT_EQ(lp[0].y, 1.f);
  EXPECT_EQ(lp[0].z, 0.5f);
  EXPECT_EQ(lp[0].ring, 4);
  EXPECT_EQ(lp[0].intensity, 200.f);
  EXPECT_EQ(lp[1].ring, 9);
  EXPECT_EQ(scan.start_stamp.ns, kStamp + 10'000'000);
  EXPECT_EQ(scan.end_stamp.ns, kStamp + 60'000'000);
  EXPECT_EQ(lp[1].offset_ns, 50'000'000);
}

TEST(CloudScan, WithoutARingFieldRingsComeFromElevation) {
  const auto calibration =
      drivers::velodyne::builtin_calibration(drivers::velodyne::ProductId::kVlp32c);
  ASSERT_EQ(calibration.lasers.size(), 32u);
  const std::vector<std::uint16_t> rings = drivers::velodyne::rings_by_elevation(calibration);
  std::vector<double> elevations;
  for (const auto& l : calibration.lasers) elevations.push_back(l.vert_correction_rad);
  // One point per laser, 20 m away at the laser's elevation (in laser-id order, not by ring).
  const std::vector<ser::Field> fields{{"x", 0, 7, 1}, {"y", 4, 7, 1}, {"z", 8, 7, 1}};
  std::vector<std::byte> data(32 * 12);
  for (std::size_t id = 0; id < 32; ++id) {
    const double e = calibration.lasers[id].vert_correction_rad;
    const float xyz[3] = {static_cast<float>(20 * std::cos(e)), 0.f,
                          static_cast<float>(20 * std::sin(e))};
    std::memcpy(data.data() + id * 12, xyz, 12);
  }
  const auto bytes = ser::point_cloud2(1, kStamp, "velodyne", 1, 32, fields, 12, data);
  PayloadPool pool(1, 64 * sizeof(LidarPoint));
  ros1::CloudScanConfig config;
  config.ring_elevations_rad = elevations;
  ros1::CloudScanDecoder decoder(pool, config);
  LidarScan scan;
  ros1::CloudScanInfo info;
  ASSERT_EQ(decoder.decode(decode(bytes), HostTime::from_ns(kStamp), scan, info),
            ros1::CloudScanStatus::kOk);
  EXPECT_TRUE(info.derived_ring);
  EXPECT_FALSE(info.has_time);
  ASSERT_EQ(scan.point_count, 32u);
  const auto lp = scan.points.as<LidarPoint>();
  for (std::size_t id = 0; id < 32; ++id) EXPECT_EQ(lp[id].ring, rings[id]) << "laser " << id;
  // No time field: every point at header.stamp (no deskew possible).
  EXPECT_EQ(scan.start_stamp.ns, kStamp);
  EXPECT_EQ(scan.end_stamp.ns, kStamp);
  for (std::size_t id = 0; id < 32; ++id) EXPECT_EQ(lp[id].offset_ns, 0);
}

TEST(CloudScan, InvalidPointsAreLeftOutAndCounted) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<P> points{{nan, nan, nan, 0, 0, 0.f},  // organized-cloud gap
                              {0.1f, 0, 0, 0, 1, 0.01f},   // inside min range
                              {500, 0, 0, 0, 2, 0.02f},    // beyond max range
                              {10, 0, 0, 0, 3, 0.03f},
                              {0, 20, 0, 0, 4, 0.05f}};
  PayloadPool pool(1, 16 * sizeof(LidarPoint));
  ros1::CloudScanConfig config;
  config.min_range_m = 0.5f;
  config.max_range_m = 120.f;
  ros1::CloudScanDecoder decoder(pool, config);
  LidarScan scan;
  ros1::CloudScanInfo info;
  ASSERT_EQ(
      decoder.decode(decode(velodyne_cloud(points, kStamp)), HostTime::from_ns(kStamp), scan, info),
      ros1::CloudScanStatus::kOk);
  EXPECT_EQ(info.points_in, 5u);
  EXPECT_EQ(info.points_invalid, 3u);
  ASSERT_EQ(scan.point_count, 2u);
  const auto lp = scan.points.as<LidarPoint>();
  EXPECT_EQ(lp[0].ring, 3);
  EXPECT_EQ(lp[1].ring, 4);
  // The scan spans the points kept.
  EXPECT_NEAR(static_cast<double>(scan.start_stamp.ns - kStamp), 0.03e9, 100);
  EXPECT_NEAR(static_cast<double>(lp[1].offset_ns), 0.02e9, 100);
}

TEST(CloudScan, AFullOrSmallPoolIsAStatusNotACrash) {
  std::vector<P> points;
  for (int i = 0; i < 10; ++i) {
    const auto f = static_cast<float>(i);
    points.push_back({10.f + f, 0, 0, 0, 0, 0.001f * f});
  }
  // The decoded cloud views the message bytes: they must outlive it.
  const std::vector<std::byte> message = velodyne_cloud(points, kStamp);
  const auto cloud = decode(message);
  PayloadPool small(1, 4 * sizeof(LidarPoint));
  ros1::CloudScanDecoder decoder(small, {});
  LidarScan scan;
  ros1::CloudScanInfo info;
  ASSERT_EQ(decoder.decode(cloud, HostTime::from_ns(kStamp), scan, info),
            ros1::CloudScanStatus::kOk);
  EXPECT_EQ(scan.point_count, 4u);
  EXPECT_EQ(info.points_overflow, 6u);
  EXPECT_EQ(scan.points.as<LidarPoint>()[3].offset_ns, 3'000'000);
  // The only buffer is still held by `scan`: the next cloud has none, and the gap shows.
  LidarScan next;
  EXPECT_EQ(decoder.decode(cloud, HostTime::from_ns(kStamp), next, info),
            ros1::CloudScanStatus::kNoBuffer);
  scan = LidarScan{};
  ASSERT_EQ(decoder.decode(cloud, HostTime::from_ns(kStamp), next, info),
            ros1::CloudScanStatus::kOk);
  EXPECT_EQ(next.sequence, 2u) << "sequence 1 was dropped";
}

TEST(CloudScan, ACloudWithoutCoordinatesIsRejected) {
  const std::vector<ser::Field> fields{{"range", 0, 7, 1}, {"intensity", 4, 7, 1}};
  std::vector<std::byte> data(8);
  const auto bytes = ser::point_cloud2(1, kStamp, "x", 1, 1, fields, 8, data);
  PayloadPool pool(1, 4 * sizeof(LidarPoint));
  ros1::CloudScanDecoder decoder(pool, {});
  LidarScan scan;
  ros1::CloudScanInfo info;
  EXPECT_EQ(decoder.decode(decode(bytes), HostTime::from_ns(kStamp), scan, info),
            ros1::CloudScanStatus::kNoXyz);
}

}  // namespace ros1_cloud_scan_test
}  // namespace posed::testing
