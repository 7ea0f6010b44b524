// What ROS 2 tools see of posed replaying a simulated drive with a lidar: a separate, ROS 2-typed
// DDS reader gets rt/posed/cloud in the Velodyne driver's PointCloud2 layout, one per scan posed
// says it wrote, and a reader that joins late still gets rt/posed/map (transient-local); a
// recording made with --record-outputs carries the same topics as ros2msg channels.

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <thread>

#include "daemon/dds/subscriber.hpp"
#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/ros2_schemas.hpp"
#include "tests/integration/hil_helpers.hpp"
#include "tests/integration/posed_process.hpp"

namespace posed::testing {
namespace ros_tools_test {
namespace {

using namespace std::chrono_literals;

// 1..99 like the other integration tests, +40 apart from theirs in a process with the same id.
int test_domain() { return 1 + static_cast<int>((::getpid() + 40) % 99); }

std::string dds_yaml() {
  return "dds:\n  domain_id: " + std::to_string(test_domain()) +
         "\n  cyclonedds_config: " + source_dir() + "/config/cyclonedds-loopback.xml\n";
}

dds::DdsConfig reader_config() {
  dds::DdsConfig c;
  c.domain_id = static_cast<std::uint32_t>(test_domain());
  c.cyclonedds_xml_path = source_dir() + "/config/cyclonedds-loopback.xml";
  return c;
}

/// A 4 s street drive (lidar and IMU), made once per test process.
const std::string& recording() {
  static TempDir dir;
  static const std::string path = [] {
    const std::string p = dir.file("street.mcap");
    PosedProcess sim({build_dir() + "/tools/posectl/posectl", "sim", "--scenario", "street_night",
                      "--duration", "4", "--seed", "9", "--no-cameras", "--config",
                      source_dir() + "/config/posed.yaml", "-o", p},
                     {}, dir);
    EXPECT_EQ(sim.wait_for_exit(60s), 0) << sim.err();
    return p;
  }();
  return path;
}

template <class T>
T field_at(const dds::CloudMessage& m, std::size_t point, std::uint32_t offset) {
  T v{};
  std::memcpy(&v, m.data.data() + point * m.point_step + offset, sizeof v);
  return v;
}

TEST(Ros2Tools, CloudsInTheVelodyneLayoutOnePerScanAndTheMapForALateJoiner) {
  TempDir dir;
  const std::string config = dir.write("posed.yaml", dds_yaml() + "publish:\n  map_rate_hz: 1\n");
  std::string error;
  // Pose too: posed waits for a pose or odom reader before a replay's first sample.
  const std::array topics = {dds::Topic::kPose, dds::Topic::kCloud};
  auto reader = dds::Subscriber::create(reader_config(), topics, error);
  ASSERT_TRUE(reader) << error;
  // At recorded timing, so the late reader below joins while posed still runs.
  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording(),
                      "--rate", "1", "--wait-subscribers", "5"},
                     {}, dir);
  std::vector<dds::Received<dds::CloudMessage>> clouds;
  std::vector<dds::Received<dds::PoseMessage>> poses;
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (clouds.size() < 10 && std::chrono::steady_clock::now() < deadline) {
    reader->wait(Duration::from_ms(100));
    reader->take_cloud(dds::Topic::kCloud, clouds);
    reader->take_pose(poses);
  }
  ASSERT_GE(clouds.size(), 10u) << posed.err();

  const std::array late_topics = {dds::Topic::kMap};
  auto late = dds::Subscriber::create(reader_config(), late_topics, error);
  ASSERT_TRUE(late) << error;
  std::vector<dds::Received<dds::CloudMessage>> maps;
  while (maps.empty() && std::chrono::steady_clock::now() < deadline) {
    late->wait(Duration::from_ms(50));
    late->take_cloud(dds::Topic::kMap, maps);
    reader->take_cloud(dds::Topic::kCloud, clouds);  // keep up: the reader holds 2 at most
  }
  ASSERT_EQ(maps.size(), 1u) << "a late joiner gets the latest map, and only that";
  EXPECT_EQ(maps[0].frame_id, "map");
  EXPECT_EQ(maps[0].msg.point_step, 12u);
  EXPECT_GT(maps[0].msg.width, 1000u);

  std::optional<int> exit_code;
  while (!exit_code && std::chrono::steady_clock::now() < deadline) {
    reader->wait(Duration::from_ms(20));
    reader->take_cloud(dds::Topic::kCloud, clouds);
    exit_code = posed.wait_for_exit(1ms);
  }
  ASSERT_EQ(exit_code, 0) << posed.err();
  reader->take_cloud(dds::Topic::kCloud, clouds);
  // Every cloud posed wrote reached the reader (reliable, keep-last 2, a reader that keeps up).
  const long long written = hil_helpers::number_after(posed.out(), "  point clouds        ");
  EXPECT_EQ(static_cast<long long>(clouds.size()), written) << posed.out();
  const long long scans = hil_helpers::number_after(posed.out(), "  scan matching       ");
  EXPECT_EQ(written, scans) << "one cloud per matched scan:\n" << posed.out();

  const char* names[] = {"x", "y", "z", "intensity", "ring", "time"};
  const std::uint32_t offsets[] = {0, 4, 8, 12, 16, 18};
  const std::uint8_t types[] = {7, 7, 7, 7, 4, 7};
  for (const auto& r : clouds) {
    const dds::CloudMessage& m = r.msg;
    EXPECT_EQ(r.frame_id, "velodyne");
    ASSERT_EQ(m.fields.size(), 6u);
    for (std::size_t i = 0; i < 6; ++i) {
      EXPECT_EQ(m.fields[i].name, names[i]);
      EXPECT_EQ(m.fields[i].offset, offsets[i]);
      EXPECT_EQ(m.fields[i].datatype, types[i]);
      EXPECT_EQ(m.fields[i].count, 1u);
    }
    EXPECT_EQ(m.point_step, 22u);
    ASSERT_EQ(m.data.size(), std::size_t{m.width} * 22u);
    // A VLP-32C turn in the street: tens of thousands of returns.
    EXPECT_GT(m.width, 20000u);
    EXPECT_TRUE(m.is_dense);
    float min_time = 0, max_time = -1;
    std::uint16_t max_ring = 0;
    for (std::size_t i = 0; i < m.width; i += 97) {
      const float t = field_at<float>(m, i, 18);
      min_time = std::min(min_time, t);
      max_time = std::max(max_time, t);
      max_ring = std::max(max_ring, field_at<std::uint16_t>(m, i, 16));
      const Eigen::Vector3f p(field_at<float>(m, i, 0), field_at<float>(m, i, 4),
                              field_at<float>(m, i, 8));
      EXPECT_LT(p.norm(), 200.0f);
    }
    // Firings span one 10 Hz turn and end at the stamp.
    EXPECT_GE(min_time, -0.12f);
    EXPECT_LT(min_time, -0.08f);
    EXPECT_LE(max_time, 0.0f);
    EXPECT_GT(max_time, -0.01f);
    EXPECT_EQ(max_ring, 31);
  }
}

TEST(Ros2Tools, RecordOutputsPutsTheTopicsInTheRecordingWithTheirSchemas) {
  TempDir dir;
  const std::string config = dir.write("posed.yaml", dds_yaml());
  const std::string out = dir.file("outputs.mcap");
  PosedProcess posed(
      {build_dir() + "/daemon/posed", "--config", config, "--replay", recording(), "--max-speed",
       "--wait-subscribers", "0", "--record", out, "--record-outputs", "all"},
      {}, dir);
  ASSERT_EQ(posed.wait_for_exit(60s), 0) << posed.err();
  drivers::recording::McapReader r;
  std::string error;
  ASSERT_TRUE(r.open(out, error)) << error;
  std::map<std::string, int> count;
  drivers::recording::McapMessage m;
  while (r.next(m)) {
    const auto* schema = r.schema(m.channel->schema_id);
    if (schema == nullptr) continue;  // raw sensor bytes
    EXPECT_EQ(schema->encoding, "ros2msg") << m.channel->topic;
    EXPECT_EQ(m.channel->message_encoding, "cdr");
    const std::string text(reinterpret_cast<const char*>(schema->data.data()), schema->data.size());
    EXPECT_EQ(text, drivers::recording::ros2::schema_for(schema->name)) << schema->name;
    ASSERT_GE(m.data.size(), 4u);
    EXPECT_EQ(static_cast<int>(m.data[1]), 1) << "CDR little endian";
    ++count[m.channel->topic + " " + schema->name];
  }
  for (const char* expected :
       {"/posed/odom nav_msgs/msg/Odometry", "/posed/pose geometry_msgs/msg/PoseStamped",
        "/tf tf2_msgs/msg/TFMessage", "/tf_static tf2_msgs/msg/TFMessage",
        "/posed/path nav_msgs/msg/Path", "/diagnostics diagnostic_msgs/msg/DiagnosticArray",
        "/posed/status posed_msgs/msg/Status", "/posed/cloud sensor_msgs/msg/PointCloud2",
        "/posed/map sensor_msgs/msg/PointCloud2"}) {
    EXPECT_GT(count[expected], 0) << expected;
  }
  EXPECT_EQ(count["/tf_static tf2_msgs/msg/TFMessage"], 1);
  EXPECT_EQ(count["/posed/cloud sensor_msgs/msg/PointCloud2"],
            hil_helpers::number_after(posed.out(), "  point clouds        "));
  EXPECT_EQ(count["/tf tf2_msgs/msg/TFMessage"],
            count["/posed/pose geometry_msgs/msg/PoseStamped"]);
}

}  // namespace
}  // namespace ros_tools_test
}  // namespace posed::testing
