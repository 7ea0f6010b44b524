// rt/posed/cloud and rt/posed/map (daemon/cloud_messages, daemon/cloud_output): the PointCloud2
// layout the ROS 2 Velodyne driver uses, the firing times relative to the stamp, and the clouds
// reaching a separate DDS reader from CloudOutput's own thread with every point of the scan.

#include "daemon/cloud_output.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "daemon/cloud_messages.hpp"
#include "daemon/config/config_loader.hpp"
#include "daemon/dds/message_tap.hpp"
#include "daemon/dds/publisher.hpp"
#include "daemon/dds/subscriber.hpp"
#include "tests/unit/dds/test_domain.hpp"

namespace posed {
namespace {

template <class T>
T field_at(const dds::CloudMessage& m, std::size_t point, std::uint32_t offset) {
  T v{};
  std::memcpy(&v, m.data.data() + point * m.point_step + offset, sizeof v);
  return v;
}

std::vector<lidar::ScanPoint> three_points() {
  std::vector<lidar::ScanPoint> points(3);
  for (int i = 0; i < 3; ++i) {
    auto& p = points[static_cast<std::size_t>(i)];
    p.p = Eigen::Vector3f(1.0f + static_cast<float>(i), -2.0f, 0.5f);
    p.intensity = 10.0f * static_cast<float>(i);
    p.ring = static_cast<std::uint16_t>(31 - i);
    p.offset_ns = i * 50'000'000;  // 0, 50, 100 ms into a 100 ms scan
  }
  return points;
}

TEST(ScanCloud, HasTheVelodyneDriversFieldsAndFiringTimesBeforeTheStamp) {
  const auto points = three_points();
  MatchedScan scan;
  scan.index = 1;
  scan.start_stamp = HostTime::from_ns(1'000'000'000);
  scan.stamp = HostTime::from_ns(1'100'000'000);
  scan.points_lidar = points;
  dds::CloudMessage m;
  scan_cloud(scan, WallTime::from_ns(42), "velodyne", m);

  EXPECT_EQ(m.frame_id, "velodyne");
  EXPECT_EQ(m.stamp, WallTime::from_ns(42));
  ASSERT_EQ(m.width, 3u);
  EXPECT_EQ(m.point_step, 22u);
  ASSERT_EQ(m.data.size(), 66u);
  const std::vector<std::pair<std::string, std::uint8_t>> names = {
      {"x", 7}, {"y", 7}, {"z", 7}, {"intensity", 7}, {"ring", 4}, {"time", 7}};
  ASSERT_EQ(m.fields.size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(m.fields[i].name, names[i].first);
    EXPECT_EQ(m.fields[i].datatype, names[i].second) << names[i].first;
    EXPECT_EQ(m.fields[i].count, 1u);
  }
  EXPECT_EQ(m.fields[4].offset, 16u);
  EXPECT_EQ(m.fields[5].offset, 18u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(field_at<float>(m, i, 0), points[i].p.x());
    EXPECT_EQ(field_at<float>(m, i, 4), -2.0f);
    EXPECT_EQ(field_at<float>(m, i, 12), points[i].intensity);
    EXPECT_EQ(field_at<std::uint16_t>(m, i, 16), points[i].ring);
  }
  // The stamp is the scan's end: the first firing was 100 ms before it, the last at it.
  EXPECT_FLOAT_EQ(field_at<float>(m, 0, 18), -0.1f);
  EXPECT_FLOAT_EQ(field_at<float>(m, 1, 18), -0.05f);
  EXPECT_FLOAT_EQ(field_at<float>(m, 2, 18), 0.0f);
}

/// A core that has matched one scan of `points` and holds a local map of `map`.
class MatchedCore final : public FusionCore {
 public:
  std::vector<lidar::ScanPoint> points;
  std::vector<Eigen::Vector3f> map;
  std::uint64_t index = 0;
  HostTime end;

  void add_imu(const ImuSample&, std::vector<NavState>&) override {}
  void add_scan(LidarScan, std::vector<NavState>&) override {}
  EstimatorMode mode() const override { return EstimatorMode::kLidarInertial; }
  std::string_view description() const override { return "test"; }
  FusionFigures figures() const override { return {}; }
  void local_map(std::vector<Eigen::Vector3f>& out) const override { out = map; }
  bool latest_matched_scan(MatchedScan& out) const override {
    if (index == 0) return false;
    out.index = index;
    out.stamp = end;
    out.start_stamp = end - Duration::from_ms(100);
    out.points_lidar = points;
    return true;
  }
};

TEST(CloudOutput, ScansAndTheMapReachASeparateReaderWithEveryPoint) {
  dds::DdsConfig dds_config = dds::test::loopback_config();
  std::string error;
  auto publisher = dds::Publisher::create(dds_config, error);
  ASSERT_NE(publisher, nullptr) << error;
  const std::array topics = {dds::Topic::kCloud, dds::Topic::kMap};
  auto reader = dds::Subscriber::create(dds_config, topics, error);
  ASSERT_NE(reader, nullptr) << error;
  ASSERT_TRUE(dds::test::eventually(
      [&] { return publisher->matched_subscribers(dds::Topic::kCloud) == 1; }));

  config::PosedConfig config = config::default_config();
  config.dds.lidar_frame = "velodyne";
  config.dds.map_frame = "map";
  config.publish.map_rate_hz = 1.0;
  MatchedCore core;
  // A per-run token in the sizes: a stranger's cloud or map on the same random domain (another
  // test's, left for late joiners) is told apart by them.
  const int token = static_cast<int>(std::random_device{}() % 1000);
  const int scan_points = 5000 + token, map_points = 1234 + token;
  for (int i = 0; i < scan_points; ++i) {
    lidar::ScanPoint p;
    p.p = Eigen::Vector3f(static_cast<float>(i) * 0.01f, 1.0f, 2.0f);
    p.ring = static_cast<std::uint16_t>(i % 32);
    core.points.push_back(p);
  }
  core.map.assign(static_cast<std::size_t>(map_points), Eigen::Vector3f(3, 4, 5));
  {
    CloudOutput output(config, *publisher, HostToWall{Duration::from_ns(0)});
    output.after_scan(core);  // nothing matched yet: nothing built
    for (int k = 1; k <= 3; ++k) {
      core.index = static_cast<std::uint64_t>(k);
      core.end = HostTime::from_ns(k * 100'000'000LL);
      output.after_scan(core);
      output.after_scan(core);  // the same scan again: not sent twice
    }
    output.stop();
    const CloudOutputCounters c = output.counters();
    EXPECT_EQ(c.clouds + c.clouds_replaced, 3u);
    EXPECT_EQ(c.maps, 1u);  // 1 Hz over 0.2 s of scans
    EXPECT_EQ(c.failed, 0u);
  }

  std::vector<dds::Received<dds::CloudMessage>> clouds, maps, taken;
  const auto take = [&](dds::Topic topic, int width, auto& into) {
    taken.clear();
    reader->take_cloud(topic, taken);
    for (auto& r : taken) {
      if (r.msg.width == static_cast<std::uint32_t>(width)) into.push_back(std::move(r));
    }
  };
  ASSERT_TRUE(dds::test::eventually([&] {
    take(dds::Topic::kCloud, scan_points, clouds);
    take(dds::Topic::kMap, map_points, maps);
    return !clouds.empty() && clouds.back().msg.stamp == WallTime::from_ns(300'000'000) &&
           !maps.empty();
  }));
  const auto n = static_cast<std::size_t>(scan_points);
  for (const auto& r : clouds) {
    EXPECT_EQ(r.frame_id, "velodyne");
    EXPECT_EQ(r.msg.data.size(), n * 22u);
    EXPECT_EQ(field_at<std::uint16_t>(r.msg, n - 1, 16), (n - 1) % 32);
  }
  EXPECT_EQ(clouds.back().msg.stamp, WallTime::from_ns(300'000'000));
  EXPECT_EQ(maps.front().frame_id, "odom");  // the estimator's local map
  EXPECT_EQ(maps.front().msg.point_step, 12u);
}

/// Counts what a tap would forward (Foxglove, the recording) per topic.
class CountingTap final : public dds::MessageTap {
 public:
  bool wants(dds::Topic topic) const override { return topic == dds::Topic::kCloud; }
  void deliver(dds::Topic topic, WallTime, std::span<const std::byte> cdr) override {
    if (topic == dds::Topic::kCloud) {
      ++clouds;
      bytes = cdr.size();
    }
  }
  std::atomic<int> clouds{0};
  std::atomic<std::size_t> bytes{0};
};

TEST(CloudOutput, NoReaderNoTapNoCloudButTheMapStillGoesOutForLateJoiners) {
  dds::DdsConfig dds_config = dds::test::loopback_config();
  std::string error;
  auto publisher = dds::Publisher::create(dds_config, error);
  ASSERT_NE(publisher, nullptr) << error;
  config::PosedConfig config = config::default_config();
  MatchedCore core;
  core.points.resize(100);
  core.map.resize(10);
  core.index = 1;
  core.end = HostTime::from_ns(1'000'000'000);
  {
    CloudOutput output(config, *publisher, HostToWall{Duration::from_ns(0)});
    output.after_scan(core);
    output.stop();
    EXPECT_EQ(output.counters().clouds, 0u);  // nobody reads rt/posed/cloud: not built
    EXPECT_EQ(output.counters().maps, 1u);
  }
  // A tap that wants clouds makes them worth building, DDS reader or not.
  CountingTap tap;
  publisher->set_tap(&tap);
  {
    CloudOutput output(config, *publisher, HostToWall{Duration::from_ns(0)});
    core.index = 2;
    output.after_scan(core);
    output.stop();
    EXPECT_EQ(output.counters().clouds, 1u);
  }
  publisher->set_tap(nullptr);
  EXPECT_EQ(tap.clouds.load(), 1);
  EXPECT_GT(tap.bytes.load(), 100u * 22u);
}

}  // namespace
}  // namespace posed
