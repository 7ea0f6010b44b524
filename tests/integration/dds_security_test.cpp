// DDS Security as a user sets it up: `posectl security init` makes a keystore, posed publishes
// with its "posed" enclave, and separate `posectl echo` processes try to read rt/posed/odom: the
// authorised "posectl" enclave receives; a participant without security, one with a certificate
// from another CA, and one authenticated by the right CA but without read permission get nothing,
// and the first two do not even discover the writer (matched publishers 0: discovery is
// encrypted); a reader's enclave cannot write posed's topics. A half-configured dds.security stops
// posed at start-up with file, line and key.

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "daemon/dds/publisher.hpp"
#include "tests/integration/posed_process.hpp"

namespace posed::testing {
namespace dds_security_test {

using namespace std::chrono_literals;

// Apart from the daemon (+0), lio (+25), replay (+50) and hil (+75) tests of the same process id.
int test_domain() { return 1 + static_cast<int>((::getpid() + 12) % 99); }

std::string posectl() { return build_dir() + "/tools/posectl/posectl"; }

std::string dds_section(const std::string& security) {
  return loopback_dds_yaml(test_domain()) + security;
}

void init_keystore(const TempDir& dir, const std::string& name) {
  PosedProcess init({posectl(), "security", "init", dir.file(name)}, {}, dir);
  ASSERT_EQ(init.wait_for_exit(60s), 0) << init.err();
}

std::vector<std::string> echo_argv(const std::string& enclave) {
  std::vector<std::string> argv = {posectl(),
                                   "echo",
                                   "odom",
                                   "-d",
                                   std::to_string(test_domain()),
                                   "--cyclonedds-config",
                                   loopback_xml(),
                                   "-n",
                                   "20",
                                   "-t",
                                   "8"};
  if (!enclave.empty()) {
    argv.push_back("--enclave");
    argv.push_back(enclave);
  }
  return argv;
}

TEST(DdsSecurity, OnlyTheAuthorisedReaderHearsPosed) {
  TempDir dir;
  init_keystore(dir, "keystore");
  init_keystore(dir, "foreign");
  const std::string config = dir.write(
      "posed.yaml",
      dds_section("  security:\n    enclave: " + dir.file("keystore") + "/enclaves/posed\n") +
          "imu:\n  source: synthetic\nestimator:\n  init_static_s: 0.5\n");
  TempDir posed_dir;
  PosedProcess posed({build_dir() + "/daemon/posed", "--config", config}, {}, posed_dir);

  // All four readers at once, each a process of its own as on a robot's LAN.
  TempDir authorised_dir, plain_dir, foreign_dir, unpermitted_dir;
  PosedProcess authorised(echo_argv(dir.file("keystore") + "/enclaves/posectl"), {},
                          authorised_dir);
  PosedProcess plain(echo_argv(""), {}, plain_dir);
  PosedProcess foreign(echo_argv(dir.file("foreign") + "/enclaves/posectl"), {}, foreign_dir);
  // posed's own enclave may publish rt/posed/* but not subscribe to it.
  PosedProcess unpermitted(echo_argv(dir.file("keystore") + "/enclaves/posed"), {},
                           unpermitted_dir);

  EXPECT_EQ(authorised.wait_for_exit(30s), 0) << authorised.err() << "\nposed:\n" << posed.err();
  EXPECT_NE(authorised.out().find("odom "), std::string::npos) << authorised.out();
  for (PosedProcess* outsider : {&plain, &foreign}) {
    EXPECT_EQ(outsider->wait_for_exit(30s), 1) << outsider->out() << outsider->err();
    EXPECT_NE(outsider->err().find("0 of 20 samples"), std::string::npos) << outsider->err();
    EXPECT_NE(outsider->err().find("matched publishers: 0"), std::string::npos) << outsider->err();
    EXPECT_EQ(outsider->out().find("odom "), std::string::npos) << outsider->out();
  }
  EXPECT_EQ(unpermitted.wait_for_exit(30s), 1) << unpermitted.err();
  EXPECT_NE(unpermitted.err().find("Not Allowed By Security"), std::string::npos)
      << unpermitted.err();
  EXPECT_EQ(unpermitted.out().find("odom "), std::string::npos) << unpermitted.out();

  posed.signal(SIGTERM);
  EXPECT_EQ(posed.wait_for_exit(10s), 0) << posed.err();
}

// A forger holding a reader's enclave (authenticated by posed's CA, permitted to subscribe only)
// cannot even create a writer for rt/posed/odom, so a controller never hears it.
TEST(DdsSecurity, AReadersEnclaveCannotWritePosedsTopics) {
  TempDir dir;
  init_keystore(dir, "keystore");
  dds::DdsConfig forger;
  forger.domain_id = static_cast<std::uint32_t>(test_domain());
  forger.cyclonedds_xml_path = loopback_xml();
  forger.security = dds::DdsSecurityFiles::from_enclave(dir.file("keystore") + "/enclaves/posectl");
  std::string error;
  EXPECT_EQ(dds::Publisher::create(forger, error), nullptr);
  EXPECT_NE(error.find("rt/posed/"), std::string::npos) << error;
  EXPECT_NE(error.find("Not Allowed By Security"), std::string::npos) << error;

  // The same with posed's enclave is allowed: the refusal is the permissions', not a set-up error.
  dds::DdsConfig publisher = forger;
  publisher.security =
      dds::DdsSecurityFiles::from_enclave(dir.file("keystore") + "/enclaves/posed");
  EXPECT_NE(dds::Publisher::create(publisher, error), nullptr) << error;
}

TEST(DdsSecurity, HalfAConfigurationOrAMissingFileStopsStartUp) {
  TempDir dir;
  const std::string half =
      dir.write("half.yaml",
                dds_section("  security:\n    certificate: cert.pem\n    private_key: key.pem\n"));
  PosedProcess half_posed({build_dir() + "/daemon/posed", "--config", half}, {}, dir);
  EXPECT_EQ(half_posed.wait_for_exit(10s), 2) << half_posed.err();
  EXPECT_NE(half_posed.err().find(half + ":5:5: dds.security: half-configured: "
                                         "dds.security.certificate, dds.security.private_key set "
                                         "but dds.security.identity_ca"),
            std::string::npos)
      << half_posed.err();

  init_keystore(dir, "keystore");
  const std::string enclave = dir.file("keystore") + "/enclaves/posed";
  ::unlink((enclave + "/permissions.p7s").c_str());
  const std::string missing =
      dir.write("missing.yaml", dds_section("  security:\n    enclave: " + enclave + "\n") +
                                    "imu:\n  source: synthetic\n");
  TempDir run_dir;
  PosedProcess missing_posed({build_dir() + "/daemon/posed", "--config", missing}, {}, run_dir);
  EXPECT_EQ(missing_posed.wait_for_exit(10s), 1) << missing_posed.err();
  EXPECT_NE(missing_posed.err().find("dds.sec.access.permissions " + enclave +
                                     "/permissions.p7s: cannot read"),
            std::string::npos)
      << missing_posed.err();
}

}  // namespace dds_security_test
}  // namespace posed::testing
