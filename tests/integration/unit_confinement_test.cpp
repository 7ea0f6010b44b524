// posed lives with the restrictions of its own unit file (systemd/posed.service): unit_sandbox
// applies the unit's system-call filter, address families, memory W^X rule, empty capability
// bounding set, unprivileged user, resource limits and private /proc, and posed runs under them
// a replay with all four sensors (the camera front end included) and a live UDP + pty drive. A
// system call the filter lacks kills posed with SIGSYS, so a missing entry fails these tests.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/integration/hil_drive.hpp"
#include "tests/integration/posed_process.hpp"
#include "tests/replay/recorded_poses.hpp"

namespace posed::testing {
namespace unit_confinement_test {

using namespace std::chrono_literals;

std::vector<std::string> sandbox(const std::vector<std::string>& overrides = {}) {
  std::vector<std::string> prefix = {build_dir() + "/tests/integration/unit_sandbox",
                                     source_dir() + "/systemd/posed.service"};
  prefix.insert(prefix.end(), overrides.begin(), overrides.end());
  prefix.push_back("--");
  return prefix;
}

/// The sandbox runs posed as an unprivileged user, who must reach the test's files.
void open_to_everyone(const TempDir& dir) { ::chmod(dir.path().c_str(), 0777); }

bool can_sandbox(std::string& why) {
  if (::geteuid() != 0) {
    why = "unit_sandbox needs root (it mounts a private /proc and drops to user 65534)";
    return false;
  }
  return true;
}

TEST(UnitConfinement, AReplayWithEverySensorRunsWithSchedFifoAndTheSamePoses) {
  std::string why;
  if (!can_sandbox(why)) GTEST_SKIP() << why;
  TempDir dir;
  open_to_everyone(dir);
  const std::string recording = dir.file("street.mcap");
  {
    PosedProcess sim({simulator(), "sim", "--scenario", "street_night", "--duration", "4", "--seed",
                      "8", "--config", source_dir() + "/config/posed.yaml", "-o", recording},
                     {}, dir);
    ASSERT_EQ(sim.wait_for_exit(120s), 0) << sim.err();
  }
  ::chmod(recording.c_str(), 0644);
  // The recording's camera streams run through the camera front end (OpenCV's threads included).
  // Real-time priorities as config/posed.yaml asks for them (the schema's defaults are 0).
  const std::string config =
      dir.write("posed.yaml", hil_helpers::dds_config() +
                                  "threads:\n  imu_source:\n    priority: 40\n  lidar_source:\n"
                                  "    priority: 35\n  fusion:\n    priority: 30\n  publisher:\n"
                                  "    priority: 20\n");
  ::chmod(config.c_str(), 0644);

  // The same replay three ways: as root without restrictions, under the unit, and under the unit
  // with LimitRTPRIO=0 (the control: the real-time priority comes from the limit, not from a
  // capability, and the check below can tell).
  struct Run {
    std::vector<std::string> prefix;
    std::string output;
    std::string err;
  };
  std::vector<Run> runs = {{{}, dir.file("plain.mcap"), ""},
                           {sandbox(), dir.file("confined.mcap"), ""},
                           {sandbox({"LimitRTPRIO=0"}), dir.file("no_rtprio.mcap"), ""}};
  for (Run& run : runs) {
    std::vector<std::string> argv = run.prefix;
    for (const std::string& arg :
         {build_dir() + "/daemon/posed", std::string("--config"), config, std::string("--replay"),
          recording, std::string("--max-speed"), std::string("--wait-subscribers"),
          std::string("0"), std::string("--record"), run.output}) {
      argv.push_back(arg);
    }
    TempDir out_dir;
    PosedProcess posed(argv, {}, out_dir);
    const auto exit_code = posed.wait_for_exit(120s);
    run.err = posed.err();
    ASSERT_EQ(exit_code, 0) << "(-1: killed by a signal; SIGSYS is a system call outside the "
                               "unit's SystemCallFilter)\n"
                            << run.err;
  }
  // SCHED_FIFO needs no capability, only LimitRTPRIO. sched_setscheduler is in the filter either
  // way (a call outside it would have killed posed); whether the priority is granted can only be
  // seen where the sandbox could raise the hard RLIMIT_RTPRIO to the unit's (a container without
  // CAP_SYS_RESOURCE keeps it at 0, and then the control run is all there is to see).
  const std::string no_fifo = "cannot set SCHED_FIFO";
  if (runs[1].err.find("cannot raise LimitRTPRIO") == std::string::npos) {
    EXPECT_EQ(runs[1].err.find(no_fifo), std::string::npos) << runs[1].err;
  } else {
    std::printf("SCHED_FIFO under LimitRTPRIO not checked: %s\n", runs[1].err.c_str());
  }
  EXPECT_NE(runs[2].err.find(no_fifo), std::string::npos) << runs[2].err;

  // Max-speed replays are deterministic, so the confined run's poses are the unrestricted run's.
  const auto plain = recorded_poses(runs[0].output, "/posed/pose", false);
  const auto confined = recorded_poses(runs[1].output, "/posed/pose", false);
  ASSERT_GT(plain.size(), 15u);  // 10 Hz after the 2 s standing start
  ASSERT_EQ(plain.size(), confined.size());
  for (auto a = plain.begin(), b = confined.begin(); a != plain.end(); ++a, ++b) {
    ASSERT_EQ(a->first, b->first);
    ASSERT_EQ(a->second.p_xyz_m, b->second.p_xyz_m);
    ASSERT_EQ(a->second.q_xyzw, b->second.q_xyzw);
  }
}

TEST(UnitConfinement, ALiveDriveOverUdpAndAPtyIsTracked) {
  std::string why;
  if (!can_sandbox(why)) GTEST_SKIP() << why;
  hil_helpers::run_hil_drive({sandbox(), 6, {}, {}});
}

// The sandbox itself: a call the unit does not allow ends the process, as under systemd.
TEST(UnitConfinement, TheSandboxKillsACallOutsideTheFilter) {
  std::string why;
  if (!can_sandbox(why)) GTEST_SKIP() << why;
  TempDir dir;
  // setpriority is in @system-service (through @resources), and the unit takes it away again.
  PosedProcess nice(
      {build_dir() + "/tests/integration/unit_sandbox", source_dir() + "/systemd/posed.service",
       "--", "/usr/bin/nice", "-n", "5", "/bin/true"},
      {}, dir);
  EXPECT_EQ(nice.wait_for_exit(30s), -1) << nice.err();
  PosedProcess allowed({build_dir() + "/tests/integration/unit_sandbox",
                        source_dir() + "/systemd/posed.service", "--", "/bin/true"},
                       {}, dir);
  EXPECT_EQ(allowed.wait_for_exit(30s), 0) << allowed.err();
}

// The drop-in posectl writes from a config narrows the unit's allow-list to the lidar and the
// DDS peers, adds AF_CAN for a CAN IMU, and systemd accepts the unit with it.
TEST(UnitDropin, NarrowsTheAllowListToTheConfiguredLidarAndPeers) {
  TempDir dir;
  const std::string xml =
      dir.write("cyclonedds.xml",
                "<CycloneDDS><Domain Id=\"any\"><Discovery><Peers><Peer address=\"localhost\"/>"
                "<Peer address=\"10.1.2.3\"/></Peers></Discovery></Domain></CycloneDDS>\n");
  // The shipped CAN example (its mapping) with this test's Cyclone XML and a UDP lidar.
  const std::string config = dir.write(
      "posed.yaml",
      std::regex_replace(read_file(source_dir() + "/config/imu-can-example.yaml"),
                         std::regex("cyclonedds_config: [^\n]*"), "cyclonedds_config: " + xml) +
          "lidar:\n  enabled: true\n  source: udp\n  address: 192.168.1.201\n");
  PosedProcess dropin({build_dir() + "/tools/posectl/posectl", "unit-dropin", "--config", config,
                       "--dds-peer", "192.168.7.0/24"},
                      {}, dir);
  ASSERT_EQ(dropin.wait_for_exit(30s), 0) << dropin.err();
  const std::string text = dropin.out();
  std::vector<std::string> allowed;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("IPAddressAllow=", 0) == 0) allowed.push_back(line.substr(15));
  }
  const std::vector<std::string> expected = {
      "", "localhost", "multicast", "192.168.1.201", "10.1.2.3", "192.168.7.0/24"};
  EXPECT_EQ(allowed, expected) << text;
  EXPECT_NE(text.find("\nRestrictAddressFamilies=AF_CAN\n"), std::string::npos) << text;

  // systemd takes the unit with the drop-in appended (as it merges one), and rates it no worse.
  const std::string unit_text = read_file(source_dir() + "/systemd/posed.service");
  const std::string merged =
      std::regex_replace(unit_text, std::regex(R"(ExecStart=/usr/bin/posed)"),
                         "ExecStart=/bin/true") +
      text.substr(text.find("[Service]"));
  TempDir unit_dir;
  const std::string unit = unit_dir.write("posed.service", merged);
  PosedProcess verify({"/usr/bin/systemd-analyze", "verify", "--man=no", unit}, {}, dir);
  EXPECT_EQ(verify.wait_for_exit(30s), 0);
  EXPECT_EQ(verify.out() + verify.err(), "");

  // A lidar address that is not one is refused with the file named.
  const std::string bad = dir.write("bad.yaml",
                                    "lidar:\n  enabled: true\n  source: udp\n  "
                                    "address: velodyne.local\n");
  PosedProcess refused({build_dir() + "/tools/posectl/posectl", "unit-dropin", "--config", bad}, {},
                       dir);
  EXPECT_EQ(refused.wait_for_exit(30s), 2);
  EXPECT_NE(refused.err().find("bad.yaml: lidar.address 'velodyne.local'"), std::string::npos)
      << refused.err();
}

}  // namespace unit_confinement_test
}  // namespace posed::testing
