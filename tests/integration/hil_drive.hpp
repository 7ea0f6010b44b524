#pragma once
// Hardware-in-the-loop replay as a user runs it: `posectl sim` records a short street drive,
// a *live* posed listens on a UDP port and reads the A9 from a serial device path, and
// `posectl replay` re-emits the recording onto a real UDP socket and a real pty at the recorded
// timing. posed cannot tell it from the sensors: its poses, captured over DDS by a separate
// participant, must follow the simulator's ground truth (ATE after SE(3) alignment), once the
// replay's time shift (printed in its summary) maps them onto the recording's clock.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "daemon/dds/subscriber.hpp"
#include "tests/integration/hil_helpers.hpp"
#include "tests/integration/posed_process.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/eval/trajectory_io.hpp"

namespace posed::testing::hil_helpers {

struct HilDrive {
  /// started before posed's own arguments, so a test can run it under a sandbox
  std::vector<std::string> posed_prefix;
  /// of the simulated street drive [s]
  int duration_s = 15;
  /// run on a thread of its own while the replay plays, with posed's lidar data port, until
  /// `stop` is set (a test's extra traffic)
  std::function<void(std::uint16_t data_port, const std::atomic<bool>& stop)> alongside;
  /// more `posectl replay` arguments (--fault ...); with faults, not every packet arrives, so
  /// the counts are left to the test
  std::vector<std::string> replay_args;
  /// also the D435i's IMU: simulated, re-emitted as IIO devices (posectl replay --iio) and read
  /// live by posed (realsense_imu.enabled, its sysfs_root and dev_dir pointed at them)
  bool realsense_imu = false;
};

/// What the drive's two processes printed at exit.
struct HilDriveResult {
  std::string posed_summary;
  std::string replay_summary;
  std::string posed_log;
  /// what posed published, and the ATE of its poses against the ground truth [m]
  std::size_t poses = 0;
  double ate_m = 0;
  /// the longest time between two consecutive poses [s]
  double max_pose_gap_s = 0;
};

/// Drives a live posed with `posectl replay` of a simulated street drive over UDP and a pty, and
/// checks that every packet arrived and the poses follow the ground truth.
inline void run_hil_drive(const HilDrive& drive, HilDriveResult* result_out = nullptr) {
  using namespace std::chrono_literals;
  const std::vector<std::string>& posed_prefix = drive.posed_prefix;
  const int duration_s = drive.duration_s;
  TempDir dir;
  const std::string posectl = build_dir() + "/tools/posectl/posectl";
  const std::string recording = dir.file("street.mcap");
  const std::string truth = dir.file("truth.tum");
  {
    std::vector<std::string> sim_argv = {simulator(),
                                         "sim",
                                         "--scenario",
                                         "street_night",
                                         "--duration",
                                         std::to_string(duration_s),
                                         "--seed",
                                         "8",
                                         "--no-cameras",
                                         "--config",
                                         source_dir() + "/config/posed.yaml",
                                         "-o",
                                         recording,
                                         "--gt",
                                         truth};
    if (drive.realsense_imu) sim_argv.push_back("--realsense-imu");
    PosedProcess sim(sim_argv, {}, dir);
    ASSERT_EQ(sim.wait_for_exit(120s), 0) << sim.err();
  }

  const std::uint16_t data_port = free_udp_port();
  const std::uint16_t position_port = free_udp_port();
  const std::string device = dir.file("a9");
  const std::string iio_dir = dir.file("iio");
  const std::string realsense_imu =
      drive.realsense_imu ? "realsense_imu:\n  enabled: true\n  sysfs_root: " + iio_dir +
                                "/sys\n  dev_dir: " + iio_dir + "/dev\n"
                          : std::string();
  const std::string config =
      dir.write("posed.yaml", dds_config() + "imu:\n  source: serial\n  serial_device: " + device +
                                  "\nlidar:\n  enabled: true\n  source: udp\n  address: 127.0.0.1\n"
                                  "  data_port: " +
                                  std::to_string(data_port) + "\n  position_port: " +
                                  std::to_string(position_port) + "\n" + realsense_imu);

  dds::DdsConfig reader_config;
  reader_config.domain_id = static_cast<std::uint32_t>(test_domain());
  reader_config.cyclonedds_xml_path = loopback_xml();
  std::string error;
  const std::array topics = {dds::Topic::kPose};
  auto reader = dds::Subscriber::create(reader_config, topics, error);
  ASSERT_TRUE(reader) << error;

  // The driver under test first, as on a bench: its serial device does not exist yet, so it
  // retries; the replay waits for it to open the pty before sending anything.
  TempDir posed_dir, replay_dir;
  // A sandboxed posed runs as another user (tests/integration/unit_sandbox): it must read its
  // config, and open the pty the replay makes (udev gives the real adapter to group posed).
  ::chmod(dir.path().c_str(), 0755);
  ::chmod(config.c_str(), 0644);
  std::vector<std::string> posed_argv = posed_prefix;
  for (const std::string& arg : {build_dir() + "/daemon/posed", std::string("--config"), config}) {
    posed_argv.push_back(arg);
  }
  PosedProcess posed(posed_argv, {}, posed_dir);
  std::vector<std::string> replay_argv = {
      posectl,
      "replay",
      recording,
      "--udp",
      "127.0.0.1:" + std::to_string(data_port) + "," + std::to_string(position_port),
      "--pty",
      device,
      "--wait-reader",
      "30"};
  for (const std::string& arg : drive.replay_args) replay_argv.push_back(arg);
  if (drive.realsense_imu) {
    replay_argv.push_back("--iio");
    replay_argv.push_back(iio_dir);
  }
  PosedProcess replay(replay_argv, {}, replay_dir);
  const bool faulted = !drive.replay_args.empty();
  std::atomic<bool> stop_alongside{false};
  std::thread alongside;
  if (drive.alongside) {
    alongside = std::thread([&] { drive.alongside(data_port, stop_alongside); });
  }
  std::vector<dds::Received<dds::PoseMessage>> poses;
  std::optional<int> replay_exit;
  const auto deadline = std::chrono::steady_clock::now() + 90s;
  bool pty_opened_to_all = false;
  while (!replay_exit && std::chrono::steady_clock::now() < deadline) {
    if (!pty_opened_to_all) pty_opened_to_all = ::chmod(device.c_str(), 0666) == 0;
    reader->wait(Duration::from_ms(100));
    reader->take_pose(poses);
    replay_exit = replay.wait_for_exit(1ms);  // looks once: 0 ms would not look at all
  }
  stop_alongside = true;
  if (alongside.joinable()) alongside.join();
  ASSERT_EQ(replay_exit.value_or(-2), 0) << replay.err() << replay.out();
  // The last scans are still in the estimator; let them out, then stop posed as systemd would.
  for (int i = 0; i < 10; ++i) {
    reader->wait(Duration::from_ms(100));
    reader->take_pose(poses);
  }
  posed.signal(SIGTERM);
  ASSERT_EQ(posed.wait_for_exit(30s), 0) << posed.err();
  reader->take_pose(poses);

  // Everything the simulator recorded went out, and posed decoded every byte of it.
  const std::string summary = replay.out();
  const long long data_packets = 1507LL * duration_s;  // the VLP-32C's 1507 packets/s
  const std::string posed_summary = posed.out();
  HilDriveResult drive_result{posed_summary, summary, posed.err()};
  if (result_out != nullptr) *result_out = drive_result;
  if (!faulted) {
    EXPECT_EQ(number_after(summary, "udp data"), data_packets) << summary;
    EXPECT_EQ(number_after(summary, "udp position"), duration_s) << summary;
    EXPECT_GT(number_after(summary, "pty"), 145 * duration_s) << summary;  // 150 Hz frames
    EXPECT_NE(summary.find("0 B discarded without a reader"), std::string::npos) << summary;
    EXPECT_EQ(number_after(posed_summary, "  lidar               "), data_packets) << posed_summary;
    EXPECT_GT(number_after(posed_summary, "  imu                 "), 145 * duration_s)
        << posed_summary;
  }

  // live wall time = recorded wall time + shift: the eval offset maps the poses back.
  const auto at = summary.find("time shift");
  ASSERT_NE(at, std::string::npos) << summary;
  const double shift_s = std::atof(summary.c_str() + at + std::string("time shift").size());
  // 10 Hz after the 2 s standstill (less the scans a fault cost)
  ASSERT_GT(poses.size(), static_cast<std::size_t>(10 * (duration_s - 2) * (faulted ? 6 : 8) / 10))
      << poses.size() << " poses from a " << duration_s << " s drive";

  eval::Trajectory estimate;
  estimate.source = "rt/posed/pose";
  for (const auto& p : poses) {
    if (!estimate.stamps.empty() && p.msg.stamp.ns <= estimate.stamps.back().ns) continue;
    estimate.stamps.push_back(eval::TrajectoryTime::from_ns(p.msg.stamp.ns));
    estimate.p_world_m.push_back(p.msg.p_map_base_m);
    estimate.R_world_body.push_back(p.msg.q_map_base.toRotationMatrix());
  }
  eval::EvalOptions options;
  options.association.est_offset = Duration::from_seconds(-shift_s);
  const eval::EvalResult result =
      eval::evaluate(eval::read_trajectory(truth, eval::TrajectoryFormat::kTum), estimate, options);
  // Nearly every pose meets a ground-truth pose within the association's 10 ms: the shift is
  // right to well under a sample.
  EXPECT_GT(result.association.size(), estimate.size() * 9 / 10)
      << result.association.size() << " of " << estimate.size() << " poses associated";
  if (result_out != nullptr) {
    result_out->poses = estimate.size();
    result_out->ate_m = result.ate_m.rmse;
    for (std::size_t i = 1; i < estimate.stamps.size(); ++i) {
      result_out->max_pose_gap_s =
          std::max(result_out->max_pose_gap_s,
                   static_cast<double>(estimate.stamps[i].ns - estimate.stamps[i - 1].ns) * 1e-9);
    }
  }
  // Measured ~1 cm on this drive; 10 cm is the bound for a 300 s run, and leaves room
  // for the scheduling noise of a loaded machine (the live pipeline may drop a late scan).
  // A faulted drive's bound is the test's.
  if (!faulted) {
    EXPECT_LT(result.ate_m.rmse, 0.10)
        << "ATE " << result.ate_m.rmse << " m over " << result.association.size() << " poses";
  }
  const auto lateness_at = summary.find("lateness (all)");
  const std::string lateness =
      lateness_at == std::string::npos
          ? std::string("?")
          : summary.substr(lateness_at, summary.find('\n', lateness_at) - lateness_at);
  std::printf("HIL replay: ATE %.4f m over %zu poses; %s\n", result.ate_m.rmse,
              result.association.size(), lateness.c_str());
}

}  // namespace posed::testing::hil_helpers
