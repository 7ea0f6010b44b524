// posed as a user runs it: a separate process on the synthetic IMU with the loopback DDS
// profile, a separate DDS participant reading rt/posed/odom, a fake systemd notify socket, and
// real signals.

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "daemon/config/config_loader.hpp"
#include "daemon/dds/subscriber.hpp"
#include "tests/integration/notify_listener.hpp"
#include "tests/integration/posed_process.hpp"

namespace posed::testing {
namespace {

using namespace std::chrono_literals;

constexpr double kRadius_m = 5.0;

// A DDS domain of its own per test process, so parallel tests and a running demo never meet:
// 1..99 (the demo uses 0, the DDS unit tests 100..200, posectl bench dds 201..229).
int test_domain() { return 1 + static_cast<int>(::getpid() % 99); }

std::string demo_like_config(const std::string& extra = "") {
  return loopback_dds_yaml(test_domain()) +
         "imu:\n  source: synthetic\n"
         "synthetic_imu:\n  radius_m: 5\n  speed_mps: 1\n  static_s: 1.5\n  ramp_s: 2\n" +
         extra + "estimator:\n  init_static_s: 0.5\n";
}

std::vector<std::string> posed_argv(const std::string& config_path) {
  return {build_dir() + "/daemon/posed", "--config", config_path};
}

dds::DdsConfig reader_config() {
  dds::DdsConfig c;
  c.domain_id = static_cast<std::uint32_t>(test_domain());
  c.cyclonedds_xml_path = loopback_xml();
  return c;
}

TEST(Daemon, PublishesOdomThatFollowsTheKnownMotionAndStopsOnSigterm) {
  TempDir dir;
  const std::string config = dir.write("posed.yaml", demo_like_config());
  std::string error;
  const std::array topics = {dds::Topic::kOdom, dds::Topic::kStatus};
  auto reader = dds::Subscriber::create(reader_config(), topics, error);
  ASSERT_TRUE(reader) << error;

  PosedProcess posed(posed_argv(config), {}, dir);
  std::vector<dds::Received<dds::OdomMessage>> odom;
  std::vector<dds::Received<dds::StatusMessage>> status;
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (odom.size() < 600 && std::chrono::steady_clock::now() < deadline) {
    reader->wait(Duration::from_ms(100));
    reader->take_odom(odom);
    reader->take_status(status);
  }
  ASSERT_GE(odom.size(), 100u) << "stderr:\n" << posed.err();

  // Every pose lies on the known circle (centre (0, R), level) with the heading of its tangent;
  // before the motion starts, at the origin.
  std::vector<double> latency_ms;
  WallTime previous_stamp;
  for (const auto& r : odom) {
    const auto& m = r.msg;
    EXPECT_EQ(r.frame_id, "odom");  // REP-105: odometry is continuous in odom
    EXPECT_EQ(r.child_frame_id, "base_link");
    EXPECT_GT(m.stamp, previous_stamp);
    previous_stamp = m.stamp;
    const Eigen::Vector3d p = m.p_map_base_m;
    EXPECT_NEAR(p.z(), 0.0, 0.01);
    const double from_centre = std::hypot(p.x(), p.y() - kRadius_m);
    EXPECT_NEAR(from_centre, kRadius_m, 0.01) << p.transpose();
    const double arc_angle = std::atan2(p.x(), kRadius_m - p.y());
    const Eigen::Vector3d heading = m.q_map_base * Eigen::Vector3d::UnitX();
    const double yaw = std::atan2(heading.y(), heading.x());
    EXPECT_NEAR(std::remainder(yaw - arc_angle, 2 * M_PI), 0.0, 0.01);
    EXPECT_NEAR(m.v_base_mps.y(), 0.0, 0.01);  // a car does not slide sideways
    latency_ms.push_back((r.received_wall - m.stamp).seconds() * 1e3);
  }
  const double moved = odom.back().msg.p_map_base_m.norm();
  EXPECT_GT(moved, 0.1) << "the last pose should be on its way round the circle";
  std::sort(latency_ms.begin(), latency_ms.end());
  EXPECT_LT(latency_ms[latency_ms.size() / 2], 50.0) << "median stamp-to-receive latency [ms]";

  ASSERT_FALSE(status.empty());
  EXPECT_EQ(status.back().msg.estimator_mode, "strapdown");
  ASSERT_EQ(status.back().msg.streams.size(), 1u);
  EXPECT_EQ(status.back().msg.streams[0].name, "imu");
  EXPECT_EQ(status.back().msg.streams[0].health, "ok");
  EXPECT_EQ(status.back().msg.mapping.state, "off");  // no lidar, no mapping stage

  const auto t0 = std::chrono::steady_clock::now();
  posed.signal(SIGTERM);
  const auto code = posed.wait_for_exit(2s);
  ASSERT_TRUE(code.has_value()) << "posed did not exit within 2 s of SIGTERM";
  EXPECT_EQ(*code, 0) << posed.err();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 2s);
  EXPECT_NE(posed.out().find("posed summary"), std::string::npos) << posed.out();
}

// The host's wall clock steps (an NTP correction after boot; libfaketime steps the clock posed
// sees, and only that one, leaving its monotonic clock alone): posed's DDS stamps follow the
// wall clock within a poll of the main loop, and say so in the log. Before the step they agree
// with this process's clock; after it, they are 30 s ahead of it, as posed's wall clock is.
TEST(Daemon, StampsFollowAStepOfTheWallClock) {
  const std::string faketime = "/usr/lib/x86_64-linux-gnu/faketime/libfaketime.so.1";
  ASSERT_EQ(::access(faketime.c_str(), R_OK), 0)
      << faketime << " is missing: tools/install-deps installs libfaketime";
  TempDir dir;
  const std::string config = dir.write("posed.yaml", demo_like_config());
  const std::string offset_file = dir.write("faketime", "+0\n");
  std::string error;
  const std::array topics = {dds::Topic::kOdom};
  auto reader = dds::Subscriber::create(reader_config(), topics, error);
  ASSERT_TRUE(reader) << error;
  PosedProcess posed(posed_argv(config),
                     {"LD_PRELOAD=" + faketime, "FAKETIME_TIMESTAMP_FILE=" + offset_file,
                      "FAKETIME_NO_CACHE=1", "FAKETIME_DONT_FAKE_MONOTONIC=1"},
                     dir);
  // Stamp minus receive time of the odometry taken within `for_s` [s], the newest last.
  auto stamp_minus_receive_s = [&](double for_s) {
    std::vector<dds::Received<dds::OdomMessage>> odom;
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(for_s);
    while (std::chrono::steady_clock::now() < until) {
      reader->wait(Duration::from_ms(100));
      reader->take_odom(odom);
    }
    std::vector<double> out;
    for (const auto& r : odom) out.push_back((r.msg.stamp - r.received_wall).seconds());
    return out;
  };
  const std::vector<double> before = stamp_minus_receive_s(3.0);
  ASSERT_GE(before.size(), 50u) << "stderr:\n" << posed.err();
  EXPECT_NEAR(before.back(), 0.0, 0.5);

  // Replaced whole, so libfaketime never reads a half-written file.
  ASSERT_EQ(std::rename(dir.write("faketime.new", "+30\n").c_str(), offset_file.c_str()), 0);
  stamp_minus_receive_s(1.0);
  const std::vector<double> after = stamp_minus_receive_s(2.0);
  ASSERT_GE(after.size(), 50u) << "stderr:\n" << posed.err();
  for (const double d : after) EXPECT_NEAR(d, 30.0, 0.5);
  posed.signal(SIGTERM);
  ASSERT_TRUE(posed.wait_for_exit(5s).has_value());
  EXPECT_NE(posed.err().find("wall clock stepped by +30."), std::string::npos) << posed.err();
}

// What ROS 2 tools read: rt/tf carries map -> odom -> base_link with every pose, so the two
// transforms chain to the pose posed publishes; rt/tf_static carries base_link -> lidar, camera
// and thermal from the configured extrinsics, and a reader that joins later still gets it
// (transient-local); rt/posed/path ends at a published pose; rt/diagnostics has a status per
// stream and one for the estimator.
TEST(Daemon, PublishesTfPathAndDiagnosticsAsRos2ToolsExpect) {
  TempDir dir;
  const std::string config = dir.write("posed.yaml", demo_like_config());
  std::string error;
  const std::array topics = {dds::Topic::kPose, dds::Topic::kTf, dds::Topic::kPath,
                             dds::Topic::kDiagnostics};
  auto reader = dds::Subscriber::create(reader_config(), topics, error);
  ASSERT_TRUE(reader) << error;

  PosedProcess posed(posed_argv(config), {}, dir);
  std::vector<dds::Received<dds::PoseMessage>> poses;
  std::vector<dds::Received<dds::TfMessage>> tf;
  std::vector<dds::Received<dds::PathMessage>> paths;
  std::vector<dds::Received<dds::DiagnosticsMessage>> diagnostics;
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while ((tf.size() < 30 || paths.size() < 2 || diagnostics.size() < 2) &&
         std::chrono::steady_clock::now() < deadline) {
    reader->wait(Duration::from_ms(100));
    reader->take_pose(poses);
    reader->take_tf(dds::Topic::kTf, tf);
    reader->take_path(paths);
    reader->take_diagnostics(diagnostics);
  }
  reader->take_pose(poses);
  ASSERT_GE(tf.size(), 30u) << "stderr:\n" << posed.err();
  ASSERT_GE(paths.size(), 2u);
  ASSERT_GE(diagnostics.size(), 2u);

  std::map<std::int64_t, const dds::PoseMessage*> pose_at;
  for (const auto& p : poses) pose_at[p.msg.stamp.ns] = &p.msg;
  std::size_t matched = 0;
  for (const auto& r : tf) {
    ASSERT_EQ(r.msg.transforms.size(), 2u);
    const dds::TransformMessage& map_odom = r.msg.transforms[0];
    const dds::TransformMessage& odom_base = r.msg.transforms[1];
    EXPECT_EQ(map_odom.parent_frame, "map");
    EXPECT_EQ(map_odom.child_frame, "odom");
    EXPECT_EQ(odom_base.parent_frame, "odom");
    EXPECT_EQ(odom_base.child_frame, "base_link");
    // map -> odom -> base_link resolves to the pose of base_link in map.
    const Eigen::Isometry3d T_map_base =
        (Eigen::Translation3d(map_odom.p_parent_child_m) * map_odom.q_parent_child) *
        (Eigen::Translation3d(odom_base.p_parent_child_m) * odom_base.q_parent_child);
    const auto pose = pose_at.find(odom_base.stamp.ns);
    if (pose == pose_at.end()) continue;  // its pose sample not taken yet
    ++matched;
    EXPECT_LT((T_map_base.translation() - pose->second->p_map_base_m).norm(), 1e-9);
    EXPECT_LT(Eigen::Quaterniond(T_map_base.rotation()).angularDistance(pose->second->q_map_base),
              1e-9);
  }
  EXPECT_GT(matched, tf.size() / 2) << "tf stamps are not the poses' stamps";

  // The path: in map, growing, its newest pose one that went out on rt/posed/pose.
  const auto& path = paths.back();
  EXPECT_EQ(path.frame_id, "map");
  ASSERT_FALSE(path.msg.poses.empty());
  EXPECT_GE(path.msg.poses.size(), paths.front().msg.poses.size());
  const auto newest = pose_at.find(path.msg.poses.back().stamp.ns);
  ASSERT_NE(newest, pose_at.end());
  EXPECT_EQ(newest->second->p_map_base_m, path.msg.poses.back().p_map_base_m);

  // Diagnostics: the IMU stream healthy, with its figures, and the estimator.
  const auto& statuses = diagnostics.back().msg.status;
  const auto named = [&](const std::string& name) {
    return std::find_if(statuses.begin(), statuses.end(),
                        [&](const dds::DiagnosticStatusMessage& d) { return d.name == name; });
  };
  const auto imu = named("posed: imu");
  ASSERT_NE(imu, statuses.end());
  EXPECT_EQ(imu->level, dds::DiagnosticStatusMessage::kOk) << imu->message;
  EXPECT_NE(std::find_if(imu->values.begin(), imu->values.end(),
                         [](const auto& kv) { return kv.first == "decoded" && kv.second != "0"; }),
            imu->values.end());
  EXPECT_NE(named("posed: estimator"), statuses.end());

  // A reader that joins now, long after posed sent its static transforms, still gets them.
  const std::array static_topic = {dds::Topic::kTfStatic};
  auto late = dds::Subscriber::create(reader_config(), static_topic, error);
  ASSERT_TRUE(late) << error;
  std::vector<dds::Received<dds::TfMessage>> statics;
  const auto static_deadline = std::chrono::steady_clock::now() + 10s;
  while (statics.empty() && std::chrono::steady_clock::now() < static_deadline) {
    late->wait(Duration::from_ms(100));
    late->take_tf(dds::Topic::kTfStatic, statics);
  }
  ASSERT_EQ(statics.size(), 1u);
  const auto& transforms = statics.front().msg.transforms;
  ASSERT_EQ(transforms.size(), 3u);
  const config::LoadResult loaded = config::load_config_file(config);
  ASSERT_TRUE(loaded.ok()) << loaded.error_text();
  const auto matrix = [](const config::Transform4& T) {
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) m(r, c) = T[static_cast<std::size_t>(r * 4 + c)];
    return m;
  };
  const auto& e = loaded.config.extrinsics;
  const Eigen::Matrix4d expected[] = {matrix(e.T_imu_lidar), matrix(e.T_imu_cam),
                                      matrix(e.T_imu_cam) * matrix(e.T_cam_thermal)};
  const char* children[] = {"velodyne", "camera_color_optical_frame", "thermal_optical_frame"};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(transforms[i].parent_frame, "base_link");
    EXPECT_EQ(transforms[i].child_frame, children[i]);
    EXPECT_LT((transforms[i].p_parent_child_m - expected[i].block<3, 1>(0, 3)).norm(), 1e-9);
    const Eigen::Quaterniond q_expected(Eigen::Matrix3d(expected[i].block<3, 3>(0, 0)));
    EXPECT_LT(transforms[i].q_parent_child.angularDistance(q_expected), 1e-6) << children[i];
  }
  // Not the identity: the rig's extrinsics really went out.
  EXPECT_GT(transforms[0].p_parent_child_m.norm() + transforms[1].p_parent_child_m.norm(), 0.01);
  posed.signal(SIGTERM);
  EXPECT_EQ(posed.wait_for_exit(10s), 0) << posed.err();
}

TEST(Daemon, TellsSystemdReadyThenFeedsTheWatchdogThenStopping) {
  TempDir dir;
  const std::string config = dir.write("posed.yaml", demo_like_config());
  NotifyListener systemd("posed-test-notify-" + std::to_string(::getpid()));
  PosedProcess posed(posed_argv(config), {systemd.env(), "WATCHDOG_USEC=300000"}, dir,
                     /*set_watchdog_pid=*/true);

  const auto first = systemd.collect(10s, "READY=1");
  ASSERT_FALSE(first.empty()) << posed.err();
  EXPECT_NE(first.back().text.find("READY=1"), std::string::npos);

  const auto running = systemd.collect(1500ms);
  const auto pings = std::count_if(running.begin(), running.end(), [](const auto& m) {
    return m.text.find("WATCHDOG=1") != std::string::npos;
  });
  // WATCHDOG_USEC/2 = 150 ms: about 10 in 1.5 s.
  EXPECT_GE(pings, 6) << "watchdog pings in 1.5 s";
  EXPECT_TRUE(std::any_of(running.begin(), running.end(), [](const auto& m) {
    return m.text.find("STATUS=") != std::string::npos;
  }));

  posed.signal(SIGTERM);
  const auto stopping = systemd.collect(3s, "STOPPING=1");
  ASSERT_FALSE(stopping.empty());
  EXPECT_NE(stopping.back().text.find("STOPPING=1"), std::string::npos);
  const auto code = posed.wait_for_exit(2s);
  ASSERT_TRUE(code.has_value());
  EXPECT_EQ(*code, 0);
}

TEST(Daemon, WatchdogStopsWhenAStageStallsAndStatusNamesIt) {
  TempDir dir;
  // The fake IMU hangs in read() 2 s into its motion, like a stuck driver.
  const std::string config = dir.write(
      "posed.yaml", demo_like_config("  hang_after_s: 2\nwatchdog:\n  stage_deadline_s: 0.3\n"));
  NotifyListener systemd("posed-test-stall-" + std::to_string(::getpid()));
  PosedProcess posed(posed_argv(config), {systemd.env(), "WATCHDOG_USEC=200000"}, dir, true);

  const auto messages = systemd.collect(5s);
  const auto first_stall = std::find_if(messages.begin(), messages.end(), [](const auto& m) {
    return m.text.find("imu_source") != std::string::npos;
  });
  ASSERT_NE(first_stall, messages.end()) << "no STATUS= naming the stalled stage; stderr:\n"
                                         << posed.err();
  const auto pings_before = std::count_if(messages.begin(), first_stall, [](const auto& m) {
    return m.text.find("WATCHDOG=1") != std::string::npos;
  });
  const auto pings_after = std::count_if(first_stall, messages.end(), [](const auto& m) {
    return m.text.find("WATCHDOG=1") != std::string::npos;
  });
  EXPECT_GE(pings_before, 5) << "the watchdog was fed while every stage ran";
  EXPECT_EQ(pings_after, 0) << "WATCHDOG=1 must stop while a stage is stalled";

  posed.signal(SIGTERM);
  const auto code = posed.wait_for_exit(2s);
  ASSERT_TRUE(code.has_value()) << "a stalled source must still stop on SIGTERM";
  EXPECT_EQ(*code, 0);
}

TEST(Daemon, LidarCapturePlayedAsLiveReachesTheFusionCoreAsScans) {
  const char* env = std::getenv("POSED_REALDATA");
  const std::string realdata = env ? env : source_dir() + "/../shared/realdata";
  const std::string pcap = realdata + "/velodyne_vlp32c/vlp32c_nebula_5scans.pcap";
  const std::string calibration = realdata + "/velodyne_calib/VLP-32c.xml";
  if (!std::ifstream(pcap) || !std::ifstream(calibration)) {
    GTEST_SKIP() << "real VLP-32C capture not found at " << pcap << " (set POSED_REALDATA)";
  }
  TempDir dir;
  // The capture holds the front half-turns only (270..90 deg); cutting at 180 deg gives one scan
  // per half-turn, and a last sliver where the recorder spliced the final packet.
  const std::string config =
      dir.write("posed.yaml",
                demo_like_config("lidar:\n  enabled: true\n  source: pcap\n  pcap_file: " + pcap +
                                 "\n  calibration: " + calibration + "\n  cut_azimuth_deg: 180\n"));
  PosedProcess posed(posed_argv(config), {}, dir);
  std::this_thread::sleep_for(3s);
  posed.signal(SIGTERM);
  const auto code = posed.wait_for_exit(2s);
  ASSERT_TRUE(code.has_value()) << "posed did not exit within 2 s of SIGTERM";
  EXPECT_EQ(*code, 0) << posed.err();
  const std::string out = posed.out();
  EXPECT_NE(out.find("lidar               379 decoded"), std::string::npos) << out;
  EXPECT_NE(out.find("0 malformed, 0 dropped"), std::string::npos) << out;
  EXPECT_NE(out.find("lidar scans         6 assembled"), std::string::npos) << out;
  EXPECT_NE(out.find("6 reached the fusion core"), std::string::npos) << out;
}

TEST(Daemon, BadConfigStopsStartupNamingFileLineAndKey) {
  TempDir dir;
  const std::string config = dir.write("bad.yaml", "imu:\n  rate_hz: 5000\n  sourse: serial\n");
  PosedProcess posed(posed_argv(config), {}, dir);
  const auto code = posed.wait_for_exit(5s);
  ASSERT_TRUE(code.has_value());
  EXPECT_EQ(*code, 2);
  EXPECT_NE(posed.err().find(config + ":2:12: imu.rate_hz: 5000 is out of range [1, 2000] Hz"),
            std::string::npos)
      << posed.err();
  EXPECT_NE(posed.err().find(config + ":3:3: imu.sourse: unknown key (did you mean 'imu.source'?)"),
            std::string::npos)
      << posed.err();
}

TEST(Daemon, HelpAndPrintConfig) {
  TempDir dir;
  {
    PosedProcess posed({build_dir() + "/daemon/posed", "--help"}, {}, dir);
    ASSERT_EQ(posed.wait_for_exit(5s), 0);
    EXPECT_NE(posed.out().find("--print-config"), std::string::npos);
  }
  {
    PosedProcess posed({build_dir() + "/daemon/posed", "--print-config", "--config",
                        source_dir() + "/config/posed.yaml"},
                       {}, dir);
    ASSERT_EQ(posed.wait_for_exit(5s), 0);
    EXPECT_NE(posed.out().find("gravity_mps2: 9.805  # [m/s^2]"), std::string::npos) << posed.out();
  }
}

}  // namespace
}  // namespace posed::testing
