// The fusion stage's merge: with recordings as Sources it must hand the core one order, by
// stamp, however the producer threads are scheduled.

#include "daemon/pipeline/fusion_stage.hpp"

#include <gtest/gtest.h>

#include <random>
#include <thread>

#include "daemon/config/config_loader.hpp"

namespace posed::pipeline {
namespace {

// Records what it was handed: +stamp for IMU, -stamp for scans, and for camera frames
// 1e9 + stamp (visible) and 2e9 + stamp (thermal), so the kind and the stamp survive.
constexpr std::int64_t kVisibleTag = 1'000'000'000;
constexpr std::int64_t kThermalTag = 2'000'000'000;
std::int64_t stamp_of_entry(std::int64_t e) { return std::llabs(e) % kVisibleTag; }

class OrderRecorder final : public FusionCore {
 public:
  explicit OrderRecorder(std::vector<std::int64_t>& order) : order_(order) {}
  void add_imu(const ImuSample& sample, std::vector<NavState>& states) override {
    order_.push_back(sample.stamp.ns);
    NavState s;
    s.stamp = sample.stamp;
    states.push_back(s);
  }
  void add_scan(LidarScan scan, std::vector<NavState>&) override {
    order_.push_back(-scan.end_stamp.ns);
  }
  void add_image(CameraStream stream, Image image, std::vector<NavState>&) override {
    order_.push_back((stream == CameraStream::kVisible ? kVisibleTag : kThermalTag) +
                     image.stamp.ns);
  }
  EstimatorMode mode() const override { return EstimatorMode::kStrapdown; }
  std::string_view description() const override { return "order recorder"; }
  FusionFigures figures() const override { return {}; }

 private:
  std::vector<std::int64_t>& order_;
};

std::vector<std::int64_t> run_merge(unsigned seed) {
  config::PosedConfig config = config::default_config();
  config.threads = {};
  SpscQueue<ImuItem> imu(8, DropPolicy::kBlockWithTimeout, std::chrono::seconds(10));
  SpscQueue<ScanItem> scans(2, DropPolicy::kBlockWithTimeout, std::chrono::seconds(10));
  SpscQueue<ImageItem> visible(2, DropPolicy::kBlockWithTimeout, std::chrono::seconds(10));
  SpscQueue<ImageItem> thermal(2, DropPolicy::kBlockWithTimeout, std::chrono::seconds(10));
  SpscQueue<StateItem> states(4096, DropPolicy::kBlockWithTimeout, std::chrono::seconds(10));
  Wakeup ready, publisher;
  Heartbeat heartbeat("fusion");
  FusionCounters counters;
  std::vector<std::int64_t> order;
  FusionStage stage(config, std::make_unique<OrderRecorder>(order),
                    FusionInputs{&imu, &scans, &visible, &thermal},
                    /*in_stamp_order=*/true, states, ready, publisher, heartbeat, counters);

  // Producers with random pauses: the interleaving differs from run to run.
  std::thread imu_producer([&] {
    std::mt19937 rng(seed);
    for (int i = 1; i <= 300; ++i) {
      ImuSample s;
      s.stamp = HostTime::from_ns(i * 1000);
      imu.push(ImuItem{s, false, {}});
      ready.signal();
      if (rng() % 7 == 0) std::this_thread::sleep_for(std::chrono::microseconds(rng() % 300));
    }
    imu.push(ImuItem{{}, true, {}});
    ready.signal();
  });
  std::thread scan_producer([&] {
    std::mt19937 rng(seed * 31 + 1);
    for (int i = 1; i <= 30; ++i) {
      LidarScan scan;
      scan.end_stamp = HostTime::from_ns(i * 10000 + 500);
      scans.push(ScanItem{std::move(scan), false, {}});
      ready.signal();
      std::this_thread::sleep_for(std::chrono::microseconds(rng() % 500));
    }
    scans.push(ScanItem{{}, true, {}});
    ready.signal();
  });
  // Cameras at their own rates, exposure stamps between the IMU samples' (15 Hz and 25 Hz
  // against a 1 kHz IMU and 100 Hz lidar in this compressed time base).
  const auto camera_producer = [&](SpscQueue<ImageItem>& queue, int frames, std::int64_t period,
                                   unsigned rng_seed) {
    return std::thread([&queue, &ready, frames, period, rng_seed] {
      std::mt19937 rng(rng_seed);
      for (int i = 1; i <= frames; ++i) {
        Image image;
        image.stamp = HostTime::from_ns(i * period + 250);
        queue.push(ImageItem{std::move(image), false, {}});
        ready.signal();
        std::this_thread::sleep_for(std::chrono::microseconds(rng() % 700));
      }
      queue.push(ImageItem{{}, true, {}});
      ready.signal();
    });
  };
  std::thread visible_producer = camera_producer(visible, 4, 66'667, seed * 7 + 3);
  std::thread thermal_producer = camera_producer(thermal, 7, 40'000, seed * 11 + 5);
  stage.run();
  imu_producer.join();
  scan_producer.join();
  visible_producer.join();
  thermal_producer.join();
  EXPECT_EQ(counters.frames_fused[0].load(), 4u);
  EXPECT_EQ(counters.frames_fused[1].load(), 7u);
  EXPECT_EQ(counters.scans_fused.load(), 30u);
  EXPECT_EQ(counters.states.load(), 300u);
  return order;
}

TEST(FusionStage, RecordingsAreMergedByStampWhateverTheScheduling) {
  const std::vector<std::int64_t> first = run_merge(1);
  ASSERT_EQ(first.size(), 341u);
  // Stamp order across all four streams.
  for (std::size_t i = 1; i < first.size(); ++i) {
    EXPECT_LE(stamp_of_entry(first[i - 1]), stamp_of_entry(first[i])) << "at " << i;
  }
  for (unsigned seed = 2; seed < 6; ++seed) EXPECT_EQ(run_merge(seed), first) << "seed " << seed;
}

}  // namespace
}  // namespace posed::pipeline
