// posectl replay --fault: which messages each fault touches, and how it is spelled.

#include "tools/hil/hil_faults.hpp"

#include <gtest/gtest.h>

namespace posed::hil {
namespace {

TEST(HilFaults, ParsesKindOutputAndWindowAndRefusesWhatItCannotRead) {
  HilFault f;
  std::string error;
  ASSERT_TRUE(parse_hil_fault("drop:lidar@5+2", f, error)) << error;
  EXPECT_EQ(f.kind, HilFaultKind::kDrop);
  EXPECT_EQ(f.target, HilFaultTarget::kLidar);
  EXPECT_DOUBLE_EQ(f.start_s, 5);
  EXPECT_DOUBLE_EQ(f.duration_s, 2);
  EXPECT_EQ(to_string(f), "drop:lidar@5+2");
  ASSERT_TRUE(parse_hil_fault("unplug@3.5+1", f, error)) << error;
  EXPECT_EQ(to_string(f), "unplug@3.5+1");
  ASSERT_TRUE(parse_hil_fault("corrupt@1+0.5", f, error)) << error;
  EXPECT_EQ(f.target, HilFaultTarget::kAll);
  EXPECT_FALSE(parse_hil_fault("drop:camera@1+1", f, error));
  EXPECT_NE(error.find("unknown output 'camera'"), std::string::npos) << error;
  EXPECT_FALSE(parse_hil_fault("melt@1+1", f, error));
  EXPECT_NE(error.find("unknown kind 'melt'"), std::string::npos) << error;
  EXPECT_FALSE(parse_hil_fault("drop@1", f, error));
  EXPECT_FALSE(parse_hil_fault("drop@1+0", f, error));
}

TEST(HilFaults, EachFaultTouchesItsOutputsInsideItsWindowOnly) {
  HilFaults faults({{HilFaultKind::kDrop, HilFaultTarget::kLidar, 1, 1},
                    {HilFaultKind::kDelay, HilFaultTarget::kImu, 3, 1},
                    {HilFaultKind::kDuplicate, HilFaultTarget::kAll, 5, 1},
                    {HilFaultKind::kUnplug, HilFaultTarget::kAll, 7, 1}});
  EXPECT_TRUE(faults.judge(1.5, HilOutput::kUdpData).drop);
  EXPECT_TRUE(faults.judge(1.5, HilOutput::kUdpPosition).drop);
  EXPECT_FALSE(faults.judge(1.5, HilOutput::kSerial).drop);
  EXPECT_FALSE(faults.judge(2.0, HilOutput::kUdpData).drop) << "the window is [1, 2)";
  EXPECT_TRUE(faults.judge(3.2, HilOutput::kSerial).delay);
  EXPECT_FALSE(faults.judge(3.2, HilOutput::kUdpData).delay);
  EXPECT_TRUE(faults.judge(5.0, HilOutput::kUdpData).duplicate);
  EXPECT_TRUE(faults.judge(5.0, HilOutput::kSerial).duplicate);
  // Unplugged: the pty's bytes are lost, the lidar's still go out.
  EXPECT_TRUE(faults.unplugged(7.5));
  EXPECT_FALSE(faults.unplugged(8.0));
  EXPECT_TRUE(faults.judge(7.5, HilOutput::kSerial).drop);
  EXPECT_FALSE(faults.judge(7.5, HilOutput::kUdpData).drop);
}

TEST(HilFaults, CorruptionFlipsAFewBytesTheSameWayEveryRun) {
  const std::vector<std::byte> clean(1206, std::byte{0x5A});
  auto corrupted = [&](double t_s) {
    HilFaults faults({{HilFaultKind::kCorrupt, HilFaultTarget::kLidar, 1, 1}});
    std::vector<std::byte> bytes = clean;
    faults.corrupt(t_s, HilOutput::kUdpData, bytes);
    return bytes;
  };
  const auto a = corrupted(1.5);
  EXPECT_EQ(a, corrupted(1.5)) << "seeded";
  std::size_t changed = 0;
  for (std::size_t i = 0; i < a.size(); ++i) changed += a[i] != clean[i] ? 1 : 0;
  EXPECT_GE(changed, 10u);
  EXPECT_LE(changed, 1206u / 64);
  EXPECT_EQ(corrupted(0.5), clean);
  HilFaults imu_only({{HilFaultKind::kCorrupt, HilFaultTarget::kImu, 0, 10}});
  std::vector<std::byte> bytes = clean;
  EXPECT_FALSE(imu_only.corrupt(1, HilOutput::kUdpData, bytes));
  EXPECT_EQ(bytes, clean);
}

}  // namespace
}  // namespace posed::hil
