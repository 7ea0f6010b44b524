// The lidar-inertial estimator end to end, as a user runs it: `posectl sim` writes a recording of
// a short street drive, `posed --replay --max-speed --record` runs it through the real decoders,
// clock sync, estimator and publisher, twice. The recorded poses must follow the recorded
// ground truth, and the two replays must be bit-identical, poses and odometry.

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "drivers/recording/mcap_reader.hpp"
#include "drivers/recording/ros2_messages.hpp"
#include "tests/integration/posed_process.hpp"
#include "tests/integration/simulated_recording.hpp"
#include "tests/replay/recorded_poses.hpp"

namespace posed::testing {
// Named rather than anonymous: test binaries build as unity batches, where another file's
// helpers of the same name share the translation unit.
namespace lio_replay_test {

using namespace std::chrono_literals;
namespace rec = drivers::recording;

int test_domain() { return 1 + static_cast<int>((::getpid() + 25) % 99); }

Eigen::Vector3d position(const rec::ros2::StampedPose& p) {
  return {p.p_xyz_m[0], p.p_xyz_m[1], p.p_xyz_m[2]};
}

TEST(LioReplay, ASimulatedStreetDriveIsTrackedAndReplaysAreIdentical) {
  TempDir dir;
  const std::string recording = dir.file("street.mcap");
  ASSERT_TRUE(simulate_recording(dir, recording, "street_night", 15, 8, {"--no-cameras"}).ok);
  const std::string config = dir.write("posed.yaml", loopback_dds_yaml(test_domain()));
  std::vector<std::string> outputs;
  for (const char* name : {"a.mcap", "b.mcap"}) {
    PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording,
                        "--max-speed", "--wait-subscribers", "0", "--record", dir.file(name)},
                       {}, dir);
    ASSERT_EQ(posed.wait_for_exit(120s), 0) << posed.err();
    EXPECT_NE(posed.out().find("lidar-inertial"), std::string::npos) << posed.out();
    outputs.push_back(dir.file(name));
  }
  const auto a = recorded_poses(outputs[0], "/posed/pose", false);
  const auto b = recorded_poses(outputs[1], "/posed/pose", false);
  const auto truth = recorded_poses(recording, "/posed/ground_truth", true);
  ASSERT_GT(a.size(), 120u);  // 10 Hz after the 2 s standing start
  ASSERT_EQ(a.size(), b.size());
  for (auto ia = a.begin(), ib = b.begin(); ia != a.end(); ++ia, ++ib) {
    ASSERT_EQ(ia->first, ib->first);
    ASSERT_EQ(ia->second.p_xyz_m, ib->second.p_xyz_m);
    ASSERT_EQ(ia->second.q_xyzw, ib->second.q_xyzw);
  }
  // rt/posed/odom, propagated on the IMU stage's thread apart from the back end, is bit-identical
  // too: a max-speed replay's odometry waits for the back end's anchors as the data orders them.
  const auto odom_a = recorded_poses(outputs[0], "/posed/odom", true);
  const auto odom_b = recorded_poses(outputs[1], "/posed/odom", true);
  ASSERT_GT(odom_a.size(), 12u * 150u);  // the A9's 150 Hz after the standing start
  ASSERT_EQ(odom_a.size(), odom_b.size());
  for (auto ia = odom_a.begin(), ib = odom_b.begin(); ia != odom_a.end(); ++ia, ++ib) {
    ASSERT_EQ(ia->first, ib->first);
    ASSERT_EQ(ia->second.p_xyz_m, ib->second.p_xyz_m);
    ASSERT_EQ(ia->second.q_xyzw, ib->second.q_xyzw);
  }

  // posectl export picks posed's poses from a recording that also holds its odometry.
  {
    PosedProcess exported(
        {build_dir() + "/tools/posectl/posectl", "export", outputs[0], "--tum", dir.file("a.tum")},
        {}, dir);
    ASSERT_EQ(exported.wait_for_exit(60s), 0) << exported.err();
    EXPECT_NE(exported.err().find(std::to_string(a.size()) + " poses from /posed/pose"),
              std::string::npos)
        << exported.err();
  }

  // The poses are stamped in the recording's time base: they meet the ground truth (100 Hz)
  // within 5 ms, without any offset. ATE after the best rigid alignment.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> pairs;
  for (const auto& [stamp, p] : a) {
    auto it = truth.lower_bound(stamp - 5'000'000);
    if (it == truth.end() || std::llabs(it->first - stamp) > 5'000'000) continue;
    pairs.emplace_back(position(p), position(it->second));
  }
  ASSERT_GT(pairs.size(), a.size() * 9 / 10) << "poses not in the ground truth's time base";
  Eigen::Vector3d me = Eigen::Vector3d::Zero(), mg = Eigen::Vector3d::Zero();
  for (const auto& [e, g] : pairs) {
    me += e;
    mg += g;
  }
  me /= static_cast<double>(pairs.size());
  mg /= static_cast<double>(pairs.size());
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (const auto& [e, g] : pairs) C += (g - mg) * (e - me).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1;
  const Eigen::Matrix3d R = svd.matrixU() * D * svd.matrixV().transpose();
  double sq = 0;
  for (const auto& [e, g] : pairs) sq += (R * (e - me) + mg - g).squaredNorm();
  const double ate = std::sqrt(sq / static_cast<double>(pairs.size()));
  // Measured 1-2 cm on such runs; 10 cm is the bound for a 300 s run.
  EXPECT_LT(ate, 0.10) << "ATE " << ate << " m over " << pairs.size() << " poses";
}

TEST(LioReplay, EveryLoopPassStartsAfreshAndRepeatsTheFirst) {
  // `posed --replay --loop`: each pass runs through a pipeline of its own, so it gives the first
  // pass's poses again (not a robot teleported back with the last pass's estimate), stamped
  // after the pass before it.
  TempDir dir;
  const std::string recording = dir.file("street.mcap");
  ASSERT_TRUE(simulate_recording(dir, recording, "street_night", 6, 8, {"--no-cameras"}).ok);
  const std::string config = dir.write("posed.yaml", loopback_dds_yaml(test_domain()));
  PosedProcess posed(
      {build_dir() + "/daemon/posed", "--config", config, "--replay", recording, "--max-speed",
       "--loop", "--passes", "3", "--wait-subscribers", "0", "--record", dir.file("loop.mcap")},
      {}, dir);
  ASSERT_EQ(posed.wait_for_exit(120s), 0) << posed.err();
  EXPECT_NE(posed.out().find("passes              3, each from a fresh start"), std::string::npos)
      << posed.out();
  EXPECT_NE(posed.err().find("--loop pass 3: ended at"), std::string::npos) << posed.err();

  const auto poses = recorded_poses(dir.file("loop.mcap"), "/posed/pose", false);
  ASSERT_GT(poses.size(), 3u * 30u);
  ASSERT_EQ(poses.size() % 3, 0u) << "every pass gives as many poses as the first";
  const std::vector<std::pair<std::int64_t, rec::ros2::StampedPose>> all(poses.begin(),
                                                                         poses.end());
  const std::size_t n = all.size() / 3;
  const std::int64_t pass_period_ns = all[n].first - all[0].first;
  // The pass lasts about the recording's 6 s; the next starts right after it.
  EXPECT_GT(pass_period_ns, 5'900'000'000);
  EXPECT_LT(pass_period_ns, 6'100'000'000);
  for (std::size_t pass = 1; pass < 3; ++pass) {
    for (std::size_t i = 0; i < n; ++i) {
      const auto& first = all[i];
      const auto& again = all[pass * n + i];
      ASSERT_EQ(again.first - first.first, static_cast<std::int64_t>(pass) * pass_period_ns)
          << "pass " << pass + 1 << " pose " << i;
      ASSERT_LT((position(again.second) - position(first.second)).norm(), 1e-6)
          << "pass " << pass + 1 << " pose " << i << " differs from the first pass's";
    }
  }
}

TEST(LioReplay, ALidarOutageIsReportedInTheDataTimeAndTheOdometryCarriesOnThroughIt) {
  // posectl sim --fault: the lidar falls silent for 2 s. posed keeps running and publishing
  // odometry through it, logs the stream unhealthy about a second into the silence and healthy
  // again when it speaks, in the data's time (at full speed too: the fusion stage judges a
  // replay's silences as it merges the streams in stamp order).
  TempDir dir;
  const std::string recording = dir.file("street.mcap");
  {
    const Simulated sim = simulate_recording(dir, recording, "street_night", 8, 8,
                                             {"--no-cameras", "--fault", "lidar_outage@4+2"});
    ASSERT_TRUE(sim.ok);
    EXPECT_NE(sim.out.find("fault lidar_outage@4+2"), std::string::npos) << sim.out;
  }
  const std::string config = dir.write("posed.yaml", loopback_dds_yaml(test_domain()));
  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording,
                      "--max-speed", "--wait-subscribers", "0", "--record", dir.file("out.mcap")},
                     {}, dir);
  ASSERT_EQ(posed.wait_for_exit(120s), 0) << posed.err();
  // posectl sim's host clock starts at 100 s (SimOptions::host_epoch_ns).
  const auto at = [&](const std::string& change) -> double {
    const std::string log = posed.err();
    const auto i = log.find("stream lidar: " + change + " at ");
    if (i == std::string::npos) return -1;
    return std::stod(log.substr(i + 18 + change.size())) - 100.0;
  };
  const double lost_s = at("ok -> no_data"), back_s = at("no_data -> ok");
  // A second into the silence, and with the first scan after it (the data's time, exactly).
  EXPECT_NEAR(lost_s, 5.0, 0.1) << posed.err();
  EXPECT_GE(back_s, 5.95) << posed.err();
  EXPECT_LE(back_s, 6.3) << posed.err();
  EXPECT_EQ(posed.err().find("stream imu:"), std::string::npos) << posed.err();
  // The scan that was open when the lidar fell silent is stale when the first packet after the
  // silence closes it: left out, said so, and neither a corrupt device time nor a degraded stream.
  EXPECT_NE(posed.err().find("the scan in progress when the data stopped"), std::string::npos)
      << posed.err();
  EXPECT_EQ(posed.err().find("stream lidar: ok -> degraded"), std::string::npos) << posed.err();
  EXPECT_EQ(posed.err().find("corrupt device time"), std::string::npos) << posed.err();
  // The summary counts it where a person looks for lost scans.
  EXPECT_NE(posed.out().find("left out: 1 open when the data stopped, 0 stamped implausibly"),
            std::string::npos)
      << posed.out();

  // The odometry went on through the silence (IMU propagation).
  const auto odom = recorded_poses(dir.file("out.mcap"), "/posed/odom", true);
  const auto truth = recorded_poses(recording, "/posed/ground_truth", true);
  ASSERT_FALSE(truth.empty());
  const std::int64_t start_ns = truth.begin()->first;
  std::size_t during = 0;
  for (const auto& [stamp, p] : odom) {
    const double t = static_cast<double>(stamp - start_ns) * 1e-9;
    during += t > 4.2 && t < 5.8;
  }
  EXPECT_GT(during, 150u) << "IMU-rate odometry (150 Hz) through the 2 s outage";
}

TEST(LioReplay, ABurstOfCorruptLidarPacketsDoesNotStopTheLidar) {
  // posectl sim --fault corrupt_burst: a second of bit-flipped packets on every stream. Corrupt
  // device times once cut so many tiny scans that every scan buffer waited in the estimator's
  // gate while the stamp-ordered merge waited for the next scan: the lidar stopped for good.
  TempDir dir;
  const std::string recording = dir.file("street.mcap");
  ASSERT_TRUE(simulate_recording(dir, recording, "street_night", 8, 8,
                                 {"--no-cameras", "--fault", "corrupt_burst@4+1"})
                  .ok);
  const std::string config = dir.write("posed.yaml", loopback_dds_yaml(test_domain()));
  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config, "--replay", recording,
                      "--max-speed", "--wait-subscribers", "0", "--record", dir.file("out.mcap")},
                     {}, dir);
  ASSERT_EQ(posed.wait_for_exit(120s), 0) << posed.err();
  // The lidar is heard again after the burst, and poses follow the scans to the end.
  EXPECT_EQ(posed.err().find("stream lidar: ok -> no_data"), std::string::npos) << posed.err();
  // Both streams are degraded in the data's time: from the first good sample after a bad one
  // (where the merge meets it, not where the stage had read ahead to: the IMU's reads seconds
  // ahead) until 2 s after the last. The lidar's packets are damaged, not all lost: from the
  // burst's first scan. Every A9 frame in the burst fails its CRC: the IMU is silent in it and
  // degraded from its first good frame. posectl sim's host clock starts at 100 s.
  const auto at = [&](const std::string& stream, const std::string& change) -> double {
    const std::string log = posed.err(), line = "stream " + stream + ": " + change + " at ";
    const auto i = log.find(line);
    if (i == std::string::npos) return -1;
    return std::stod(log.substr(i + line.size())) - 100.0;
  };
  EXPECT_GE(at("lidar", "ok -> degraded"), 4.0) << posed.err();
  EXPECT_LE(at("lidar", "ok -> degraded"), 4.2) << posed.err();
  EXPECT_GE(at("lidar", "degraded -> ok"), 6.0) << posed.err();
  EXPECT_LE(at("lidar", "degraded -> ok"), 7.3) << posed.err();
  EXPECT_GE(at("imu", "ok -> degraded"), 4.0) << posed.err();
  EXPECT_LE(at("imu", "ok -> degraded"), 5.1) << posed.err();
  EXPECT_NEAR(at("imu", "degraded -> ok") - at("imu", "ok -> degraded"), 2.0, 0.1) << posed.err();
  const auto poses = recorded_poses(dir.file("out.mcap"), "/posed/pose", false);
  const auto truth = recorded_poses(recording, "/posed/ground_truth", true);
  ASSERT_FALSE(truth.empty());
  const std::int64_t start_ns = truth.begin()->first;
  std::size_t after = 0;
  for (const auto& [stamp, p] : poses) after += static_cast<double>(stamp - start_ns) * 1e-9 > 6.0;
  EXPECT_GT(after, 15u) << "optimised poses (10 Hz) in the last 2 s, after the burst";
}

/// A whole file's bytes.
std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(LioReplay, PosectlExportPcdWritesTheMapAndItsKeyframesDeterministically) {
  TempDir dir;
  const std::string recording = dir.file("street.mcap");
  const std::string posectl = build_dir() + "/tools/posectl/posectl";
  ASSERT_TRUE(simulate_recording(dir, recording, "street_night", 12, 9,
                                 {"--no-cameras", "--gt", dir.file("truth.txt")})
                  .ok);
  for (const char* name : {"a.pcd", "b.pcd"}) {
    PosedProcess exporter({posectl, "export", recording, "--pcd", dir.file(name), "--config",
                           source_dir() + "/config/posed.yaml"},
                          {}, dir);
    ASSERT_EQ(exporter.wait_for_exit(120s), 0) << exporter.err() << exporter.out();
    EXPECT_NE(exporter.out().find("published           nothing (offline run, no DDS)"),
              std::string::npos)
        << exporter.out();
  }
  const std::string a = slurp(dir.file("a.pcd"));
  EXPECT_EQ(a, slurp(dir.file("b.pcd"))) << "two exports of one recording differ";
  EXPECT_EQ(slurp(dir.file("a.keyframes.tum")), slurp(dir.file("b.keyframes.tum")));

  // PCD v0.7: an ASCII header ending in DATA binary, then POINTS x (3 float32).
  const std::size_t data = a.find("DATA binary\n");
  ASSERT_NE(data, std::string::npos) << a.substr(0, 300);
  std::istringstream header(a.substr(0, data));
  std::string line;
  std::size_t points = 0;
  while (std::getline(header, line)) {
    if (line.rfind("POINTS ", 0) == 0) points = std::stoul(line.substr(7));
  }
  const std::string body = a.substr(data + std::strlen("DATA binary\n"));
  ASSERT_EQ(body.size(), points * 12) << "binary body does not hold POINTS x y z float32";
  EXPECT_GT(points, 20'000u) << "a 12 s street drive maps more than that";
  // Every point lies within the lidar's reach of the driven path: nothing is garbage.
  std::vector<float> xyz(points * 3);
  std::memcpy(xyz.data(), body.data(), body.size());

  // Keyframes: increasing stamps, at least a metre or a turn apart, along the true path's length.
  std::ifstream kf(dir.file("a.keyframes.tum"));
  std::vector<std::pair<double, Eigen::Vector3d>> keyframes;
  while (std::getline(kf, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream f(line);
    double t, x, y, z;
    f >> t >> x >> y >> z;
    ASSERT_TRUE(f) << line;
    keyframes.emplace_back(t, Eigen::Vector3d(x, y, z));
  }
  ASSERT_GT(keyframes.size(), 5u);
  double mapped_length = 0;
  for (std::size_t i = 1; i < keyframes.size(); ++i) {
    EXPECT_GT(keyframes[i].first, keyframes[i - 1].first);
    mapped_length += (keyframes[i].second - keyframes[i - 1].second).norm();
  }
  for (std::size_t i = 0; i < points; ++i) {
    const Eigen::Vector3d p(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    double nearest = 1e9;
    for (const auto& k : keyframes) nearest = std::min(nearest, (p - k.second).norm());
    ASSERT_LT(nearest, 120.0) << "map point " << p.transpose() << " beyond the VLP-32C's reach";
  }
  std::ifstream gt(dir.file("truth.txt"));
  std::vector<std::pair<double, Eigen::Vector3d>> truth;
  while (std::getline(gt, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream f(line);
    double t, x, y, z;
    f >> t >> x >> y >> z;
    truth.emplace_back(t, Eigen::Vector3d(x, y, z));
  }
  ASSERT_GT(truth.size(), 100u);
  double true_length = 0;
  for (std::size_t i = 1; i < truth.size(); ++i) {
    if (truth[i].first < keyframes.front().first || truth[i].first > keyframes.back().first) {
      continue;
    }
    true_length += (truth[i].second - truth[i - 1].second).norm();
  }
  ASSERT_GT(true_length, 10.0);
  // Keyframes cut corners of the true path (chords), so a little shorter, never longer.
  EXPECT_NEAR(mapped_length, true_length, 0.08 * true_length)
      << "mapped " << mapped_length << " m vs driven " << true_length << " m";
}

}  // namespace lio_replay_test
}  // namespace posed::testing
