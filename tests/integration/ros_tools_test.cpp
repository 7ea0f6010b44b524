// What ROS 2 tools see of posed replaying a simulated drive with a lidar: a separate, ROS 2-typed
// DDS reader gets rt/posed/cloud in the Velodyne driver's PointCloud2 layout, one per scan posed
// says it wrote, and a reader that joins late still gets rt/posed/map (transient-local); a
// recording made with --record-outputs carries the same topics as ros2msg channels; and
// Foxglove's own npm client (tests/node) receives every topic over posed's Foxglove WebSocket
// server and decodes every message with Foxglove's ros2msg parser and CDR reader.

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>
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

std::string dds_yaml() { return loopback_dds_yaml(test_domain()); }

dds::DdsConfig reader_config() {
  dds::DdsConfig c;
  c.domain_id = static_cast<std::uint32_t>(test_domain());
  c.cyclonedds_xml_path = loopback_xml();
  return c;
}

/// A 4 s street drive (lidar and IMU), made once per test process.
const std::string& recording() {
  static TempDir dir;
  static const std::string path = [] {
    const std::string p = dir.file("street.mcap");
    PosedProcess sim(
        {simulator(), "sim", "--scenario", "street_night", "--duration", "4", "--seed", "9",
         "--no-cameras", "--config", source_dir() + "/config/posed.yaml", "-o", p},
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
  EXPECT_EQ(maps[0].frame_id, "odom");
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

/// `name` on PATH, or "" (PosedProcess execs a path).
std::string on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::string dirs = path != nullptr ? path : "/usr/bin:/bin";
  for (std::size_t start = 0; start <= dirs.size();) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::filesystem::path candidate =
        std::filesystem::path(dirs.substr(start, end - start)) / name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return "";
}

/// "(/posed/odom 1346, /tf 90)" after `label` in posed's summary -> topic -> count.
std::map<std::string, long long> counts_in_summary(const std::string& text,
                                                   const std::string& label) {
  std::map<std::string, long long> counts;
  const auto at = text.find(label);
  if (at == std::string::npos) return counts;
  const auto open = text.find('(', at), close = text.find(')', at);
  std::stringstream items(text.substr(open + 1, close - open - 1));
  std::string topic;
  long long n = 0;
  while (items >> topic >> n) {
    counts[topic] = n;
    items.ignore(2, ' ');  // ", "
  }
  return counts;
}

TEST(Ros2Tools, FoxglovesOwnClientGetsAndDecodesEveryTopic) {
  const std::string node = on_path("node");
  const std::string client_js = source_dir() + "/tests/node/foxglove_client.mjs";
  ASSERT_FALSE(node.empty()) << "node is not on PATH: run tools/install-deps";
  ASSERT_TRUE(std::filesystem::exists(source_dir() + "/tests/node/node_modules/@foxglove"))
      << "the npm modules of tests/node are missing: run tools/install-deps";
  TempDir posed_dir, client_dir;
  const std::uint16_t port = hil_helpers::free_tcp_port();
  const std::string config = posed_dir.write(
      "posed.yaml",
      dds_yaml() + "foxglove:\n  enabled: true\n  port: " + std::to_string(port) +
          // room for the whole run, so however slowly the client reads, nothing is dropped
          "\n  max_queued_mb: 512\n");
  // posed waits for the client to subscribe to odom before the replay's first sample.
  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording(),
                      "--max-speed", "--wait-subscribers", "20"},
                     {}, posed_dir);
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (posed.err().find("foxglove: serving") == std::string::npos &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(20ms);
  }
  ASSERT_NE(posed.err().find("foxglove: serving"), std::string::npos) << posed.err();
  PosedProcess client({node, client_js, "ws://127.0.0.1:" + std::to_string(port), "--seconds", "60",
                       "--decode", "--until-close"},
                      {}, client_dir);
  ASSERT_EQ(posed.wait_for_exit(60s), 0) << posed.err();
  ASSERT_EQ(client.wait_for_exit(20s), 0) << client.err();
  const nlohmann::json report = nlohmann::json::parse(client.out());
  EXPECT_TRUE(report.value("closedByServer", false));
  EXPECT_TRUE(report["statuses"].empty()) << report["statuses"].dump();
  EXPECT_NE(posed.out().find(", 0 dropped for slow clients"), std::string::npos) << posed.out();

  // What posed says it sent on each channel is what the client received, and every message
  // decodes with Foxglove's ros2msg parser and CDR reader.
  const auto sent = counts_in_summary(posed.out(), "  foxglove            ");
  ASSERT_EQ(sent.size(), 9u) << posed.out();
  const auto& channels = report["channels"];
  for (const auto& [topic, count] : sent) {
    ASSERT_TRUE(channels.contains(topic)) << topic;
    const auto& c = channels[topic];
    EXPECT_EQ(c["messages"].get<long long>(), count) << topic;
    EXPECT_EQ(c["decoded"].get<long long>(), count) << topic;
    EXPECT_EQ(c["decodeErrors"].get<long long>(), 0) << topic << ": " << c.dump();
    EXPECT_EQ(c["encoding"], "cdr");
    EXPECT_EQ(c["schemaEncoding"], "ros2msg");
  }
  // Every odometry message posed published reached Foxglove (it subscribed before the first).
  EXPECT_EQ(sent.at("/posed/odom"),
            hil_helpers::number_after(posed.out(), "  published           "));
  EXPECT_EQ(sent.at("/posed/cloud"),
            hil_helpers::number_after(posed.out(), "  point clouds        "));
  EXPECT_EQ(channels["/posed/odom"]["schemaName"], "nav_msgs/msg/Odometry");
  EXPECT_EQ(channels["/posed/odom"]["last"]["frameId"], "odom");
  EXPECT_EQ(channels["/tf"]["last"]["transforms"],
            nlohmann::json::array({"map->odom", "odom->base_link"}));
  EXPECT_EQ(channels["/tf_static"]["messages"], 1);
  EXPECT_EQ(channels["/tf_static"]["last"]["transforms"].size(), 3u);
  const auto& cloud = channels["/posed/cloud"]["last"];
  EXPECT_EQ(cloud["frameId"], "velodyne");
  EXPECT_EQ(cloud["pointStep"], 22);
  EXPECT_EQ(cloud["fields"], nlohmann::json::array({"x:7@0", "y:7@4", "z:7@8", "intensity:7@12",
                                                    "ring:4@16", "time:7@18"}));
  EXPECT_EQ(cloud["dataBytes"].get<long long>(), cloud["width"].get<long long>() * 22);
  EXPECT_EQ(channels["/posed/map"]["last"]["frameId"], "odom");
  EXPECT_EQ(channels["/diagnostics"]["last"]["statuses"][0], "posed: imu");
  // The status's last member, decoded with the schema: a field out of place would garble it.
  EXPECT_EQ(channels["/posed/status"]["last"]["mappingState"], "mapping");
}

TEST(Ros2Tools, TheFrontEndsImageArrivesAsAJpegOfTheTrackedImage) {
  TempDir dir;
  const std::string drive = dir.file("cameras.mcap");
  {
    TempDir sim_dir;
    PosedProcess sim({simulator(), "sim", "--scenario", "street_night", "--duration", "3", "--seed",
                      "9", "--config", source_dir() + "/config/posed.yaml", "-o", drive},
                     {}, sim_dir);
    ASSERT_EQ(sim.wait_for_exit(60s), 0) << sim.err();
  }
  const std::string config = dir.write("posed.yaml", dds_yaml());
  std::string error;
  const std::array topics = {dds::Topic::kPose, dds::Topic::kImage};
  auto reader = dds::Subscriber::create(reader_config(), topics, error);
  ASSERT_TRUE(reader) << error;
  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", drive,
                      "--max-speed", "--wait-subscribers", "5"},
                     {}, dir);
  std::vector<dds::Received<dds::ImageMessage>> images;
  std::optional<int> exit_code;
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (!exit_code && std::chrono::steady_clock::now() < deadline) {
    reader->wait(Duration::from_ms(20));
    reader->take_image(images);  // keep up: the reader holds 2 at most
    exit_code = posed.wait_for_exit(1ms);
  }
  ASSERT_EQ(exit_code, 0) << posed.err();
  reader->take_image(images);
  const long long written = hil_helpers::number_after(posed.out(), "  images              ");
  ASSERT_GT(written, 5) << posed.out();  // 5 Hz over the ~2.5 s the front end runs
  EXPECT_EQ(static_cast<long long>(images.size()), written);
  for (const auto& r : images) {
    EXPECT_EQ(r.frame_id, "camera_color_optical_frame");
    EXPECT_EQ(r.msg.format, "jpeg");
    const cv::Mat decoded = cv::imdecode(r.msg.data, cv::IMREAD_COLOR);
    ASSERT_FALSE(decoded.empty()) << "not a JPEG";
    EXPECT_EQ(decoded.cols, 640);  // the D435i's colour stream as simulated
    EXPECT_EQ(decoded.rows, 480);
  }
  // At most 5 Hz of the data's time.
  for (std::size_t i = 1; i < images.size(); ++i) {
    EXPECT_GE((images[i].msg.stamp - images[i - 1].msg.stamp).seconds(), 0.2 - 1e-3);
  }
}

}  // namespace
}  // namespace ros_tools_test
}  // namespace posed::testing
