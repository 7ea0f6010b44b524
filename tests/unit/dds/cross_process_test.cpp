// Two processes on the loopback Cyclone config: discovery (unicast to localhost, participant
// index auto) and delivery over the loopback interface, not Cyclone's in-process shortcut.
// The child is this test binary re-run with a filter selecting ChildPublisher.

#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "daemon/dds/publisher.hpp"
#include "daemon/dds/subscriber.hpp"
#include "drivers/common/host_clock.hpp"
#include "tests/unit/dds/test_domain.hpp"

extern char** environ;

namespace posed::dds {
namespace {

constexpr const char* kDomainEnv = "POSED_DDS_TEST_CHILD_DOMAIN";
constexpr const char* kStampEnv = "POSED_DDS_TEST_CHILD_STAMP";

// Runs only as the child of ForkedPublisherReachesSubscriber.
TEST(DdsCrossProcess, ChildPublisher) {
  const char* domain = std::getenv(kDomainEnv);
  const char* stamp = std::getenv(kStampEnv);
  if (domain == nullptr || stamp == nullptr) GTEST_SKIP() << "child half of a two-process test";
  DdsConfig config;
  config.domain_id = static_cast<std::uint32_t>(std::stoul(domain));
  config.cyclonedds_xml_path = test::loopback_xml_path();
  std::string error;
  auto publisher = Publisher::create(config, error);
  ASSERT_NE(publisher, nullptr) << error;
  ASSERT_TRUE(test::eventually([&] { return publisher->matched_subscribers(Topic::kOdom) >= 1; }))
      << "the parent's subscriber was never discovered";
  OdomMessage msg;
  msg.stamp = WallTime::from_ns(std::stoll(stamp));
  msg.p_map_base_m = {7, 8, 9};
  // Publish until the parent leaves (it unmatches when it got the sample), at most 10 s.
  test::eventually([&] {
    publisher->publish_odom(msg);
    return publisher->matched_subscribers(Topic::kOdom) == 0;
  });
}

TEST(DdsCrossProcess, ForkedPublisherReachesSubscriber) {
  if (std::getenv(kDomainEnv) != nullptr) GTEST_SKIP() << "this is the child";
  DdsConfig config = test::loopback_config();
  std::string error;
  const std::array topics = {Topic::kOdom};
  auto subscriber = Subscriber::create(config, topics, error);
  ASSERT_NE(subscriber, nullptr) << error;

  const WallTime stamp = drivers::wall_now();
  std::vector<std::string> env_storage;
  for (char** e = environ; *e != nullptr; ++e) env_storage.emplace_back(*e);
  env_storage.push_back(std::string(kDomainEnv) + "=" + std::to_string(config.domain_id));
  env_storage.push_back(std::string(kStampEnv) + "=" + std::to_string(stamp.ns));
  std::vector<char*> envp;
  for (auto& s : env_storage) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::string self = "/proc/self/exe";
  std::string filter = "--gtest_filter=DdsCrossProcess.ChildPublisher";
  char* argv[] = {self.data(), filter.data(), nullptr};
  pid_t child = 0;
  ASSERT_EQ(posix_spawn(&child, self.c_str(), nullptr, nullptr, argv, envp.data()), 0);

  bool got = false;
  std::vector<Received<OdomMessage>> samples;
  test::eventually([&] {
    subscriber->wait(Duration::from_ms(100));
    subscriber->take_odom(samples);
    for (const auto& r : samples) {
      if (r.msg.stamp == stamp) {
        got = true;
        EXPECT_EQ(r.msg.p_map_base_m, Eigen::Vector3d(7, 8, 9));
        EXPECT_EQ(r.frame_id, "odom");
      }
    }
    samples.clear();
    return got;
  });
  subscriber.reset();  // the child stops once we are gone
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(got) << "no sample from the other process";
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "child failed, status " << status;
}

}  // namespace
}  // namespace posed::dds
