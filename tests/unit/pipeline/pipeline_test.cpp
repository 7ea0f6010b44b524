// The whole pipeline in one process (no DDS): synthetic A9 bytes -> real decoder -> ClockSync ->
// queues -> strapdown -> outputs, at full speed (not live), which must be lossless and
// deterministic.

#include "daemon/pipeline/pipeline.hpp"

#include <gtest/gtest.h>

#include <mutex>
#include <vector>

#include "daemon/config/config_loader.hpp"
#include "daemon/pipeline/source_factory.hpp"
#include "drivers/imu/a9_protocol.hpp"

namespace posed::pipeline {
namespace {

config::PosedConfig test_config() {
  config::PosedConfig c = config::default_config();
  c.imu.source = "synthetic";
  c.imu.gyro_noise_density = 0;
  c.imu.accel_noise_density = 0;
  c.threads = {};  // normal scheduling
  return c;
}

drivers::SyntheticImuConfig offline(const config::PosedConfig& c, double duration_s) {
  drivers::SyntheticImuConfig s = synthetic_imu_config(c);
  s.real_time = false;
  s.duration_s = duration_s;
  return s;
}

// Flips a byte in every `every`-th chunk so its CRC fails: the decoder must count and skip it.
class CorruptingSource final : public drivers::Source {
 public:
  CorruptingSource(std::unique_ptr<drivers::Source> inner, int every)
      : inner_(std::move(inner)), every_(every) {}
  std::string_view name() const override { return inner_->name(); }
  bool open(std::string& e) override { return inner_->open(e); }
  drivers::ReadStatus read(drivers::RawChunk& chunk, Duration timeout) override {
    const auto rs = inner_->read(chunk, timeout);
    if (rs == drivers::ReadStatus::kData && ++n_ % every_ == 0) {
      buffer_.assign(chunk.bytes.begin(), chunk.bytes.end());
      buffer_[20] ^= std::byte{0x40};
      chunk.bytes = buffer_;
    }
    return rs;
  }
  void request_stop() override { inner_->request_stop(); }
  drivers::SourceCounters counters() const override { return inner_->counters(); }
  bool live() const override { return inner_->live(); }
  std::string_view wire_format(std::uint32_t channel) const override {
    return inner_->wire_format(channel);
  }

 private:
  std::unique_ptr<drivers::Source> inner_;
  int every_;
  int n_ = 0;
  std::vector<std::byte> buffer_;
};

struct RunResult {
  std::vector<NavState> states;
  PipelineStatus final_status;
  bool merged_in_stamp_order = false;
  std::vector<NamedQueueCounters> queues;
};

RunResult run(std::unique_ptr<drivers::Source> source, const config::PosedConfig& c,
              bool live_stamps = false) {
  RunResult result;
  std::mutex m;
  PipelineOutputs outputs;
  outputs.on_state = [&](const NavState& s, const Eigen::Isometry3d&) {
    std::lock_guard lock(m);
    result.states.push_back(s);
  };
  outputs.on_status = [&](const PipelineStatus& st) {
    std::lock_guard lock(m);
    result.final_status = st;
  };
  PipelineSources sources;
  sources.imu = std::move(source);
  sources.live_stamps = live_stamps;
  Pipeline pipe(c, std::move(sources), std::move(outputs));
  std::string error;
  EXPECT_TRUE(pipe.start(error)) << error;
  result.merged_in_stamp_order = pipe.merges_in_stamp_order();
  for (int i = 0; i < 2000 && !pipe.finished(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(pipe.finished()) << "pipeline did not drain within 20 s";
  pipe.join();
  result.queues = pipe.queue_counters();
  return result;
}

TEST(Pipeline, SyntheticRunIsLosslessAndFollowsTheMotion) {
  const auto c = test_config();
  auto source = std::make_unique<drivers::SyntheticImuSource>(offline(c, 12.0));
  const sim::CircleMotion motion = source->motion();
  const RunResult r = run(std::move(source), c);

  const auto& imu = r.final_status.streams.at(0);
  EXPECT_EQ(imu.decoded, 12u * 200u + 1u);  // samples at t = 0 .. 12 s inclusive
  EXPECT_EQ(imu.malformed, 0u);
  EXPECT_EQ(imu.dropped, 0u);
  EXPECT_EQ(imu.clock_state, "locked");
  EXPECT_EQ(r.final_status.mode, EstimatorMode::kStrapdown);
  // The summary's queue line: the IMU's queue and the states', nothing for absent sensors.
  std::vector<std::string> names;
  for (const NamedQueueCounters& q : r.queues) names.push_back(q.name);
  EXPECT_EQ(names, (std::vector<std::string>{"imu", "states"}));
  ASSERT_EQ(r.queues.size(), 2u);
  const QueueCounters& imu_queue = r.queues[0].counters;
  EXPECT_EQ(imu_queue.pushed, imu.decoded + 1);  // and the end of the stream
  EXPECT_EQ(imu_queue.popped, imu_queue.pushed);
  EXPECT_EQ(imu_queue.dropped(), 0u);
  EXPECT_GE(imu_queue.high_water, 1u);
  EXPECT_LE(imu_queue.high_water, imu_queue.capacity);
  // Alignment needs 1 s of the 2 s static start; every later sample gives a state.
  ASSERT_GT(r.states.size(), 2000u);
  EXPECT_EQ(r.final_status.states, r.states.size());

  // Offline, host time = device time mapped by ClockSync from exact arrival times; the truth at
  // a state is the motion at its stamp relative to the first sample's.
  const HostTime t0 = r.states.front().stamp - Duration::from_seconds(1.0);
  const NavState& last = r.states.back();
  const auto truth = motion.at(last.stamp - t0);
  EXPECT_LT((last.p_map_base_m - truth.p_map_base_m).norm(), 0.02)
      << last.p_map_base_m.transpose() << " vs " << truth.p_map_base_m.transpose();
  EXPECT_LT(last.q_map_base.angularDistance(truth.q_map_base), 2e-3);
}

TEST(Pipeline, ReplayAtFullSpeedIsDeterministic) {
  const auto c = test_config();
  const RunResult a = run(std::make_unique<drivers::SyntheticImuSource>(offline(c, 5.0)), c);
  const RunResult b = run(std::make_unique<drivers::SyntheticImuSource>(offline(c, 5.0)), c);
  ASSERT_EQ(a.states.size(), b.states.size());
  for (std::size_t i = 0; i < a.states.size(); ++i) {
    ASSERT_EQ(a.states[i].stamp, b.states[i].stamp) << i;
    ASSERT_EQ(a.states[i].p_map_base_m, b.states[i].p_map_base_m) << i;  // bit-identical
    ASSERT_EQ(a.states[i].q_map_base.coeffs(), b.states[i].q_map_base.coeffs()) << i;
  }
}

// A replay with live stamps is taken as a live run is: merged by stamp, each scan would wait for
// the next one before the IMU past its end could release it, a scan period late.
TEST(Pipeline, OnlyRecordingsWithoutLiveStampsAreMergedByStamp) {
  const auto c = test_config();
  EXPECT_TRUE(
      run(std::make_unique<drivers::SyntheticImuSource>(offline(c, 3.0)), c).merged_in_stamp_order);
  const RunResult live_stamps =
      run(std::make_unique<drivers::SyntheticImuSource>(offline(c, 3.0)), c, true);
  EXPECT_FALSE(live_stamps.merged_in_stamp_order);
  EXPECT_GT(live_stamps.states.size(), 100u);
}

TEST(Pipeline, CorruptFramesAreCountedAndSkipped) {
  const auto c = test_config();
  auto inner = std::make_unique<drivers::SyntheticImuSource>(offline(c, 5.0));
  const RunResult r = run(std::make_unique<CorruptingSource>(std::move(inner), 10), c);
  const auto& imu = r.final_status.streams.at(0);
  EXPECT_EQ(imu.received, 5u * 200u + 1u);
  EXPECT_EQ(imu.malformed, 100u);  // every 10th of 1001 chunks
  EXPECT_EQ(imu.decoded, imu.received - imu.malformed);
  EXPECT_EQ(imu.health, "degraded");
  EXPECT_FALSE(r.states.empty());  // 5 % sample loss does not stop the estimator
}

}  // namespace
}  // namespace posed::pipeline
