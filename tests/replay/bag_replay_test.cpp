// A ROS 1 bag end to end, as a user with an M2DGR bag runs it: `posectl sim` drives the rig down
// a street; its IMU frames and Velodyne packets are decoded here exactly as posed's stages decode
// them (A9 decoder + ClockSync, ScanBuilder) and written, as M2DGR's drivers publish them, into a
// ROS 1 bag (tests/common/ros1_bag_writer.hpp): sensor_msgs/Imu on /handsfree/imu and
// sensor_msgs/PointCloud2 in velodyne_pointcloud's layout (x y z intensity ring time) on
// /velodyne_points, stamped in wall time like a real bag, plus camera topics posed has no stage
// for yet. `posectl import` turns the bag into MCAP, `posed --replay` runs it, and the poses must
// follow the simulator's ground truth.

#include <gtest/gtest.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <map>

#include "core/sync/clock_sync.hpp"
#include "daemon/config/config_loader.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "drivers/imu/a9_protocol.hpp"
#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "drivers/recording/ros2_messages.hpp"
#include "drivers/velodyne/scan_builder.hpp"
#include "tests/common/ros1_bag_writer.hpp"
#include "tests/common/ros1_serialize.hpp"
#include "tests/integration/posed_process.hpp"
#include "tests/integration/simulated_recording.hpp"
#include "tests/replay/recorded_poses.hpp"
#include "tools/eval/evaluation.hpp"

namespace posed::testing {
namespace bag_replay_test {

using namespace std::chrono_literals;
namespace rec = drivers::recording;
namespace ser = test::ros1;

int test_domain() { return 1 + static_cast<int>((::getpid() + 61) % 99); }

/// The recording's wall-minus-host offset (its "posed" metadata record) [ns].
std::int64_t host_to_wall_ns(const rec::McapReader& reader) {
  for (const auto& m : reader.metadata()) {
    if (m.name != rec::raw::kMetadataName) continue;
    const auto it = m.entries.find(std::string(rec::raw::kHostToWallKey));
    std::int64_t v = 0;
    if (it != m.entries.end())
      std::from_chars(it->second.data(), it->second.data() + it->second.size(), v);
    return v;
  }
  return 0;
}

/// A pose channel of a recording as an eval trajectory (stamps in the messages' wall time).
eval::Trajectory trajectory(const std::string& path, const std::string& topic, bool odometry) {
  const auto by_stamp = recorded_poses(path, topic, odometry);
  eval::Trajectory t;
  t.source = path + ":" + topic;
  for (const auto& [stamp, p] : by_stamp) {
    t.stamps.push_back(eval::TrajectoryTime::from_ns(stamp));
    t.p_world_m.emplace_back(p.p_xyz_m[0], p.p_xyz_m[1], p.p_xyz_m[2]);
    t.R_world_body.push_back(
        Eigen::Quaterniond(p.q_xyzw[3], p.q_xyzw[0], p.q_xyzw[1], p.q_xyzw[2]).toRotationMatrix());
  }
  return t;
}

/// Turns the simulator's raw streams into the bag M2DGR's drivers would have recorded.
class BagFromSimulation {
 public:
  explicit BagFromSimulation(const config::PosedConfig& config)
      : config_(config),
        imu_clock_(ClockSyncConfig{.kind = pipeline::clock_kind_from(config.imu.clock_kind),
                                   .nominal_rate_hz = config.imu.rate_hz,
                                   .latency = Duration::from_seconds(config.imu.clock_latency_s)}),
        pool_(8, drivers::velodyne::max_points_per_scan(config.lidar.rpm) * sizeof(LidarPoint)),
        builder_({},
                 drivers::velodyne::ScanBuilderConfig{
                     .decoder = {.min_range_m = config.lidar.min_range_m,
                                 .max_range_m = config.lidar.max_range_m},
                     .clock = {.kind = pipeline::clock_kind_from(config.lidar.clock_kind),
                               .nominal_rate_hz = 1507.0,
                               .latency = Duration::from_seconds(config.lidar.clock_latency_s)},
                     .assembler = {.cut_azimuth_cdeg = static_cast<std::uint32_t>(
                                       config.lidar.cut_azimuth_deg * 100)}},
                 pool_),
        bag_(test::Ros1BagWriter::Options::with(test::Ros1BagWriter::Compression::kLz4)) {
    imu_ = bag_.add_connection("/handsfree/imu", "sensor_msgs/Imu", std::string(ser::kImuMd5),
                               ser::kImuDefinition, "/handsfree_ros_imu");
    cloud_ = bag_.add_connection("/velodyne_points", "sensor_msgs/PointCloud2",
                                 std::string(ser::kPointCloud2Md5), ser::kPointCloud2Definition,
                                 "/velodyne_nodelet_manager");
    image_ = bag_.add_connection("/camera/color/image_raw", "sensor_msgs/Image",
                                 std::string(ser::kImageMd5), ser::kImageDefinition,
                                 "/camera/realsense2_camera");
  }

  void convert(const std::string& recording) {
    rec::McapReader reader;
    std::string error;
    ASSERT_TRUE(reader.open(recording, error)) << error;
    rec::McapMessage m;
    while (reader.next(m)) {
      const auto wire = m.channel->metadata.find(std::string(rec::raw::kWireFormatKey));
      if (wire == m.channel->metadata.end()) continue;
      const HostTime arrival = HostTime::from_ns(static_cast<std::int64_t>(m.log_time_ns));
      if (wire->second == rec::raw::kWireA9Serial) {
        a9_.feed(std::span(reinterpret_cast<const std::uint8_t*>(m.data.data()), m.data.size()),
                 [&](const drivers::a9::A9Frame& f) { on_imu(f, arrival); });
      } else if (wire->second == rec::raw::kWireVelodyneData) {
        builder_.add_data(m.data, arrival);
        drivers::velodyne::AssembledScan scan;
        while (builder_.pop(scan)) on_scan(scan.scan, arrival);
      } else if (wire->second == rec::raw::kWireVelodynePosition) {
        builder_.add_position(m.data);
      }
    }
    to_wall_ns_ = host_to_wall_ns(reader);
  }

  void save(const std::string& path) const { bag_.save(path); }
  std::size_t imu_messages() const { return imu_count_; }
  std::size_t clouds() const { return cloud_count_; }
  std::int64_t to_wall_ns() const { return to_wall_ns_; }

 private:
  // Bag time is wall time (ROS time on the recording PC): host time plus the recording's offset.
  std::uint64_t bag_time(HostTime t) const {
    return static_cast<std::uint64_t>(t.ns + to_wall_ns_);
  }

  void on_imu(const drivers::a9::A9Frame& f, HostTime arrival) {
    if (f.kind != drivers::a9::FrameKind::kSensor) return;
    const HostTime stamp = imu_clock_.map_raw(f.sensor.counter_us, arrival);
    // The A9's own axes (identity mounting); posed applies imu.R_imu_sensor on replay.
    const ImuSample s = drivers::a9::to_imu_sample(f.sensor, {}, stamp, {});
    ser::ImuValues v;
    v.w_radps = {s.angular_velocity_radps.x(), s.angular_velocity_radps.y(),
                 s.angular_velocity_radps.z()};
    v.a_mps2 = {s.specific_force_mps2.x(), s.specific_force_mps2.y(), s.specific_force_mps2.z()};
    pending_.push_back({arrival, imu_, ser::imu(imu_seq_++, stamp.ns, "imu_link", v)});
    ++imu_count_;
  }

  void on_scan(const LidarScan& scan, HostTime arrival) {
    // velodyne_pointcloud's PointXYZIRT: time [s] relative to header.stamp = the first firing.
    std::vector<std::byte> data(std::size_t{scan.point_count} * ser::kVelodynePointStep);
    const auto points = scan.points.as<LidarPoint>();
    for (std::uint32_t i = 0; i < scan.point_count; ++i) {
      std::byte* p = data.data() + std::size_t{i} * ser::kVelodynePointStep;
      const LidarPoint& lp = points[i];
      const float t = static_cast<float>(lp.offset_ns * 1e-9);
      std::memcpy(p + 0, &lp.x, 4);
      std::memcpy(p + 4, &lp.y, 4);
      std::memcpy(p + 8, &lp.z, 4);
      std::memcpy(p + 16, &lp.intensity, 4);
      std::memcpy(p + 20, &lp.ring, 2);
      std::memcpy(p + 24, &t, 4);
    }
    pending_.push_back(
        {arrival, cloud_,
         ser::point_cloud2(cloud_seq_++, scan.start_stamp.ns, "velodyne", 1, scan.point_count,
                           ser::velodyne_fields(), ser::kVelodynePointStep, data)});
    ++cloud_count_;
    // A small colour frame per scan, for the camera stage's sensor_msgs/Image path.
    std::vector<std::byte> rgb(4 * 4 * 3, std::byte{0x80});
    pending_.push_back({arrival, image_,
                        ser::image(cloud_seq_, scan.start_stamp.ns, "camera", 4, 4, "rgb8", rgb)});
  }

 public:
  /// Writes the messages gathered, shifted into wall time, in receive order, and closes the bag.
  void write_bag() {
    for (auto& p : pending_) {
      // Header stamps too: every message here starts with a Header, its stamp at byte 4.
      std::uint32_t sec = 0, nsec = 0;
      {
        std::memcpy(&sec, p.data.data() + 4, 4);
        std::memcpy(&nsec, p.data.data() + 8, 4);
        const std::int64_t wall =
            static_cast<std::int64_t>(sec) * 1'000'000'000 + nsec + to_wall_ns_;
        sec = static_cast<std::uint32_t>(wall / 1'000'000'000);
        nsec = static_cast<std::uint32_t>(wall % 1'000'000'000);
        std::memcpy(p.data.data() + 4, &sec, 4);
        std::memcpy(p.data.data() + 8, &nsec, 4);
      }
      bag_.write(p.conn, bag_time(p.arrival), p.data);
    }
    pending_.clear();
    bag_.close();
  }

 private:
  struct Pending {
    HostTime arrival;
    std::uint32_t conn;
    std::vector<std::byte> data;
  };
  const config::PosedConfig& config_;
  drivers::a9::A9Decoder a9_;
  ClockSync imu_clock_;
  PayloadPool pool_;
  drivers::velodyne::ScanBuilder builder_;
  test::Ros1BagWriter bag_;
  std::uint32_t imu_ = 0, cloud_ = 0, image_ = 0;
  std::uint32_t imu_seq_ = 0, cloud_seq_ = 0;
  std::size_t imu_count_ = 0, cloud_count_ = 0;
  std::int64_t to_wall_ns_ = 0;
  std::vector<Pending> pending_;
};

TEST(BagReplay, ASimulatedDriveImportedFromARos1BagIsTrackedInTheBagsTimeBase) {
  TempDir dir;
  const std::string posectl = build_dir() + "/tools/posectl/posectl";
  const std::string recording = dir.file("street.mcap");
  ASSERT_TRUE(simulate_recording(dir, recording, "street_night", 15, 8, {"--no-cameras"}).ok);
  const config::LoadResult loaded = config::load_config_file(source_dir() + "/config/posed.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error_text();
  auto converter = std::make_unique<BagFromSimulation>(loaded.config);
  converter->convert(recording);
  ASSERT_NE(converter->to_wall_ns(), 0) << "the simulation records a wall-clock offset";
  converter->write_bag();
  const std::string bag = dir.file("drive.bag");
  converter->save(bag);
  EXPECT_GT(converter->imu_messages(), 15u * 140u);  // 150 Hz
  EXPECT_GT(converter->clouds(), 15u * 9u);          // 10 Hz

  const std::string imported = dir.file("drive.mcap");
  {
    PosedProcess import({posectl, "import", bag, "-o", imported}, {}, dir);
    ASSERT_EQ(import.wait_for_exit(60s), 0) << import.err() << import.out();
    EXPECT_NE(import.out().find("posed streams: imu, lidar, visible"), std::string::npos)
        << import.out();
  }
  // The import keeps every topic as a ros1 channel with its schema, mapped ones marked.
  {
    rec::McapReader reader;
    std::string error;
    ASSERT_TRUE(reader.open(imported, error)) << error;
    std::map<std::string, const rec::McapChannelRecord*> by_topic;
    for (const auto& [id, c] : reader.channels()) by_topic[c.topic] = &c;
    ASSERT_TRUE(by_topic.count("/velodyne_points"));
    const rec::McapChannelRecord& cloud = *by_topic.at("/velodyne_points");
    EXPECT_EQ(cloud.message_encoding, "ros1");
    EXPECT_EQ(cloud.metadata.at("posed.stream"), "lidar");
    EXPECT_EQ(cloud.metadata.at("posed.wire_format"), "ros1:sensor_msgs/PointCloud2");
    EXPECT_EQ(cloud.metadata.at("posed.source_channel"), "0");
    EXPECT_EQ(cloud.metadata.at("md5sum"), ser::kPointCloud2Md5);
    const rec::McapSchemaRecord* schema = reader.schema(cloud.schema_id);
    ASSERT_NE(schema, nullptr);
    EXPECT_EQ(schema->name, "sensor_msgs/PointCloud2");
    EXPECT_EQ(schema->encoding, "ros1msg");
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(schema->data.data()), schema->data.size()),
              ser::kPointCloud2Definition);
    EXPECT_EQ(by_topic.at("/handsfree/imu")->metadata.at("posed.wire_format"),
              "ros1:sensor_msgs/Imu");
    EXPECT_EQ(reader.profile(), "ros1");
    // publish time = header.stamp, log time = receive time (later: a scan is published whole).
    // The first scan starts mid-rotation at start-up; every later one is whole (100 ms).
    rec::McapMessage m;
    std::size_t clouds = 0, whole_rotation_late = 0;
    while (reader.next(m)) {
      if (m.channel->topic != "/velodyne_points") continue;
      ++clouds;
      EXPECT_LT(m.publish_time_ns, m.log_time_ns);
      if (m.log_time_ns - m.publish_time_ns > 90'000'000u) ++whole_rotation_late;
    }
    EXPECT_EQ(clouds, converter->clouds());
    EXPECT_GE(whole_rotation_late + 1, clouds);
  }

  const std::string config = dir.write("posed.yaml", loopback_dds_yaml(test_domain()));
  const std::string poses = dir.file("poses.mcap");
  {
    PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", imported,
                        "--max-speed", "--wait-subscribers", "0", "--record", poses},
                       {}, dir);
    ASSERT_EQ(posed.wait_for_exit(120s), 0) << posed.err();
    EXPECT_NE(posed.out().find("lidar-inertial"), std::string::npos) << posed.out();
    EXPECT_EQ(posed.err().find("no decoder for wire format"), std::string::npos) << posed.err();
    EXPECT_EQ(posed.err().find("malformed"), std::string::npos) << posed.err();
    // The imported sensor_msgs/Image frames reach the camera stage and decode, every one.
    const std::string visible_line =
        "visible             " + std::to_string(converter->clouds()) + " decoded";
    EXPECT_NE(posed.out().find(visible_line), std::string::npos) << posed.out();
  }
  const eval::Trajectory est = trajectory(poses, "/posed/pose", false);
  const eval::Trajectory gt = trajectory(recording, "/posed/ground_truth", true);
  ASSERT_GT(est.size(), 120u);  // 10 Hz after the 2 s standing start
  // No offset given: the poses must already be in the bag's (wall) time base.
  eval::EvalOptions options;
  options.association.max_diff = Duration::from_ms(5);
  const eval::EvalResult r = eval::evaluate(gt, est, options);
  EXPECT_GT(r.association.gt_index.size(), est.size() * 9 / 10)
      << "poses not in the ground truth's time base";
  std::printf("bag replay: %zu poses, ATE RMSE %.4f m, max %.4f m\n", r.ate_m.count, r.ate_m.rmse,
              r.ate_m.max);
  // The raw-packet replay of the same drive measures 1-2 cm; 10 cm is the bound.
  EXPECT_LT(r.ate_m.rmse, 0.10) << "ATE " << r.ate_m.rmse << " m over " << r.ate_m.count;

  // The map export replays the imported bag through the same pipeline.
  {
    PosedProcess exporter({posectl, "export", imported, "--pcd", dir.file("map.pcd"), "--config",
                           source_dir() + "/config/posed.yaml"},
                          {}, dir);
    ASSERT_EQ(exporter.wait_for_exit(120s), 0) << exporter.err() << exporter.out();
  }
  const std::string pcd = read_file(dir.file("map.pcd"));
  const std::size_t points_at = pcd.find("\nPOINTS ");
  ASSERT_NE(points_at, std::string::npos) << pcd.substr(0, 300);
  EXPECT_GT(std::stoul(pcd.substr(points_at + 8)), 20'000u) << "a 15 s street drive maps more";
}

}  // namespace bag_replay_test
}  // namespace posed::testing
