// Publishing must not allocate per message beyond what Cyclone does (DESIGN.md: no allocation on
// hot paths). Cyclone allocates with malloc; posed's C++ code would allocate with operator new,
// which this binary counts while publishing.

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "daemon/dds/publisher.hpp"
#include "tests/unit/dds/test_domain.hpp"

namespace {
std::atomic<long> g_news{0};
}  // namespace

// GCC sees free() on what it believes came from operator new; here operator new is malloc.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t size) {
  g_news.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace posed::dds {
namespace {

TEST(DdsPublishAllocation, SteadyStatePublishingMakesNoCxxAllocations) {
  DdsConfig config = test::loopback_config();
  std::string error;
  auto publisher = Publisher::create(config, error);
  ASSERT_NE(publisher, nullptr) << error;

  OdomMessage odom;
  odom.stamp = WallTime::from_ns(1);
  PoseMessage pose;
  StatusMessage status;
  status.version = "posed 0.1.0 with a version string longer than SSO";
  status.streams.resize(4);
  for (auto& s : status.streams) s.name = "a stream name longer than the SSO buffer";
  ASSERT_TRUE(publisher->publish_status(status));  // first call may size buffers

  const long before = g_news.load();
  for (int i = 0; i < 100; ++i) {
    odom.stamp = odom.stamp + Duration::from_ms(2);
    ASSERT_TRUE(publisher->publish_odom(odom));
    ASSERT_TRUE(publisher->publish_pose(pose));
    ASSERT_TRUE(publisher->publish_status(status));
  }
  EXPECT_EQ(g_news.load() - before, 0);
}

}  // namespace
}  // namespace posed::dds
