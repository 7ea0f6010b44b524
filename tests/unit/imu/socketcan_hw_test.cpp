// Live SocketCAN: needs PF_CAN in the kernel and a CAN interface (POSED_CAN_IFACE, default
// vcan0: `ip link add dev vcan0 type vcan && ip link set up vcan0`). Skips, saying why, otherwise.

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "drivers/imu/socketcan_source.hpp"
#include "tests/common/socketcan_test.hpp"

namespace posed::drivers::can {
namespace {

TEST(SocketCanSource, ReceivesFramesOnALiveInterface) {
  std::string iface;
  if (const std::string why_not = test::live_can_interface(iface); !why_not.empty()) {
    GTEST_SKIP() << why_not;
  }
  SocketCanConfig cfg;
  cfg.interface = iface;
  cfg.filters = {{0x180, CAN_SFF_MASK | CAN_EFF_FLAG}};
  SocketCanSource source(cfg);
  std::string error;
  ASSERT_TRUE(source.open(error)) << error;

  // Send through a second raw socket on the same interface (vcan loops frames back).
  const int tx = test::open_can_sender(iface);
  ASSERT_GE(tx, 0) << std::strerror(errno);
  for (canid_t id : {0x181u, 0x180u}) {  // 0x181 is filtered out by the kernel
    can_frame f{};
    f.can_id = id;
    f.len = 2;
    f.data[0] = 0xAB;
    ASSERT_EQ(::write(tx, &f, sizeof f), static_cast<ssize_t>(sizeof f));
  }
  ::close(tx);
  RawChunk chunk;
  ASSERT_EQ(source.read(chunk, Duration::from_s(1)), ReadStatus::kData);
  CanFrame frame;
  ASSERT_TRUE(from_kernel_bytes(
      {reinterpret_cast<const std::uint8_t*>(chunk.bytes.data()), chunk.bytes.size()}, frame));
  EXPECT_EQ(frame.id, 0x180u);
  EXPECT_EQ(frame.data[0], 0xAB);
  EXPECT_EQ(source.read(chunk, Duration::from_ms(100)), ReadStatus::kTimeout);
}

TEST(SocketCanSource, MissingInterfaceFailsWithContext) {
  SocketCanSource source(SocketCanConfig{.interface = "nosuchcan7"});
  std::string error;
  EXPECT_FALSE(source.open(error));
  // Either PF_CAN is missing or the interface is: both must name the interface.
  EXPECT_NE(error.find("nosuchcan7"), std::string::npos) << error;
}

}  // namespace
}  // namespace posed::drivers::can
