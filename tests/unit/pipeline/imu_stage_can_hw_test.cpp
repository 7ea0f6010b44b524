// A live CAN IMU through the IMU stage: imu.source can on a real SocketCAN interface
// (POSED_CAN_IFACE, default vcan0: `ip link add dev vcan0 type vcan && ip link set up vcan0`),
// frames of config/imu-can-example.yaml's device sent through a second socket, decoded samples
// out of the stage's queue. Skips, saying why, without PF_CAN or the interface.

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "daemon/config/config_loader.hpp"
#include "daemon/pipeline/imu_stage.hpp"
#include "daemon/pipeline/source_factory.hpp"
#include "tests/common/can_imu_encoder.hpp"
#include "tests/common/socketcan_test.hpp"

namespace posed::pipeline {
namespace {

TEST(ImuStageCanLive, SamplesFromALiveInterface) {
  std::string iface;
  if (const std::string why_not = test::live_can_interface(iface); !why_not.empty()) {
    GTEST_SKIP() << why_not;
  }
  const char* src = std::getenv("POSED_SOURCE_DIR");
  ASSERT_NE(src, nullptr);
  const config::LoadResult loaded =
      config::load_config_file(std::string(src) + "/config/imu-can-example.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error_text();
  config::PosedConfig config = loaded.config;
  config.imu.can_interface = iface;
  std::string error;
  BuiltSources built = make_sources(config, error);
  ASSERT_TRUE(error.empty()) << error;
  drivers::Source& source = *built.sources.imu;
  ASSERT_TRUE(source.open(error)) << error;

  SpscQueue<ImuItem> queue(1024, DropPolicy::kDropOldest);
  Wakeup wakeup;
  Heartbeat heartbeat("imu");
  StreamCounters counters;
  ImuStage stage(config, source, queue, wakeup, heartbeat, counters);
  std::thread thread([&] { stage.run(); });
  // Stops and joins on every way out, a failed ASSERT included.
  struct Joiner {
    drivers::Source& source;
    std::thread& thread;
    ~Joiner() {
      source.request_stop();
      if (thread.joinable()) thread.join();
    }
  } joiner{source, thread};

  const int tx = test::open_can_sender(iface);
  ASSERT_GE(tx, 0) << std::strerror(errno);
  const Eigen::Vector3d gyro(0.1, -0.2, 0.3), force(0, 0, 9.80665);
  constexpr int kSamples = 20;
  for (int i = 0; i < kSamples; ++i) {
    const auto frames = test::encode_can_imu_sample(config.imu.can_mapping, gyro, force,
                                                    1000u + 5000u * static_cast<unsigned>(i));
    for (const auto& f : frames) {
      can_frame k{};
      k.can_id = f.id;
      k.len = f.len;
      std::memcpy(k.data, f.data.data(), f.len);
      ASSERT_EQ(::write(tx, &k, sizeof k), static_cast<ssize_t>(sizeof k));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::close(tx);
  for (int i = 0; i < 100 && counters.decoded.load() < kSamples; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  source.request_stop();
  thread.join();
  EXPECT_EQ(counters.decoded.load(), static_cast<std::uint64_t>(kSamples));
  EXPECT_EQ(counters.malformed.load(), 0u);
  std::size_t n = 0;
  while (auto item = queue.pop()) {
    if (item->end_of_stream) break;
    EXPECT_LT((item->sample.angular_velocity_radps - gyro).norm(), 1.5e-4);
    EXPECT_LT((item->sample.specific_force_mps2 - force).norm(), 1e-2);
    ++n;
  }
  EXPECT_EQ(n, static_cast<std::size_t>(kSamples));
}

}  // namespace
}  // namespace posed::pipeline
