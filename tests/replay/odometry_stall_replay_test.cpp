// rt/posed/odom never waits for the heavy stages: a simulated drive replayed at recorded timing
// (as live) through the whole pipeline, with the lidar stage stalled for 3 s halfway (its
// Source blocks, as a wedged driver would). The back end then waits for the lidar, so no
// optimised state comes, yet odometry keeps flowing from the IMU stage at the IMU's rate; the
// stage watchdog names the stalled stage; afterwards the back end catches up and odometry takes
// its anchors again.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <thread>

#include "daemon/config/config_loader.hpp"
#include "daemon/notify/stage_watchdog.hpp"
#include "daemon/pipeline/pipeline.hpp"
#include "daemon/pipeline/replay_sources.hpp"
#include "drivers/common/host_clock.hpp"
#include "tests/integration/posed_process.hpp"
#include "tests/integration/simulated_recording.hpp"

namespace posed::testing {
namespace odometry_stall_replay_test {

using namespace std::chrono_literals;

/// A Source that blocks once, for `stall`, when `after` has passed since its first read.
class StallingSource final : public drivers::Source {
 public:
  StallingSource(std::unique_ptr<drivers::Source> inner, Duration after, Duration stall)
      : inner_(std::move(inner)), after_(after), stall_(stall) {}
  std::string_view name() const override { return inner_->name(); }
  bool open(std::string& e) override { return inner_->open(e); }
  drivers::ReadStatus read(drivers::RawChunk& chunk, Duration timeout) override {
    const HostTime now = drivers::host_now();
    if (first_.ns == 0) first_ = now;
    if (!stalled_ && now - first_ >= after_) {
      stalled_ = true;
      stall_begin_ns.store(now.ns);
      std::this_thread::sleep_for(std::chrono::nanoseconds(stall_.ns));
      stall_end_ns.store(drivers::host_now().ns);
    }
    return inner_->read(chunk, timeout);
  }
  void request_stop() override { inner_->request_stop(); }
  drivers::SourceCounters counters() const override { return inner_->counters(); }
  bool live() const override { return inner_->live(); }
  std::string_view wire_format(std::uint32_t channel) const override {
    return inner_->wire_format(channel);
  }

  std::atomic<std::int64_t> stall_begin_ns{0};
  std::atomic<std::int64_t> stall_end_ns{0};

 private:
  std::unique_ptr<drivers::Source> inner_;
  Duration after_, stall_;
  HostTime first_;
  bool stalled_ = false;
};

TEST(OdometryStallReplay, OdomKeepsFlowingWhileTheLidarStageIsStalledAndTheWatchdogSaysSo) {
  TempDir dir;
  const std::string recording = dir.file("street.mcap");
  ASSERT_TRUE(simulate_recording(dir, recording, "street_night", 9, 3, {"--no-cameras"}).ok);
  config::LoadResult loaded = config::load_config_file(source_dir() + "/config/posed.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error_text();
  config::PosedConfig c = loaded.config;
  c.threads = {};  // normal scheduling
  ASSERT_TRUE(c.publish.odom_decoupled);

  pipeline::ReplayOptions replay;
  replay.path = recording;
  replay.rate = 1.0;  // recorded timing: the odometry runs as live
  std::string error;
  pipeline::ReplaySources sources = pipeline::make_replay_sources(replay, error);
  ASSERT_TRUE(sources.built.sources.lidar) << error;
  auto stalling = std::make_unique<StallingSource>(std::move(sources.built.sources.lidar),
                                                   Duration::from_s(5), Duration::from_s(3));
  StallingSource& lidar = *stalling;
  sources.built.sources.lidar = std::move(stalling);

  std::mutex m;
  std::vector<std::int64_t> odom_host_ns;  // when each odometry state was handed out
  std::vector<std::int64_t> pose_host_ns;  // when each optimised state was
  pipeline::PipelineOutputs outputs;
  outputs.on_odom = [&](const NavState&) {
    std::lock_guard lock(m);
    odom_host_ns.push_back(drivers::host_now().ns);
  };
  outputs.on_state = [&](const NavState& s, const Eigen::Isometry3d&) {
    std::lock_guard lock(m);
    if (s.optimised) pose_host_ns.push_back(drivers::host_now().ns);
  };
  pipeline::Pipeline pipe(c, std::move(sources.built.sources), std::move(outputs));
  ASSERT_TRUE(pipe.start(error)) << error;
  ASSERT_EQ(pipe.odometry_mode(), "imu_thread");

  notify::StageWatchdog watchdog;
  std::vector<notify::StageWatchdog::StageId> ids;
  const HostTime started = drivers::host_now();
  for (const std::string& name : pipe.stage_names()) {
    ids.push_back(watchdog.register_stage(name, Duration::from_s(1), started));
  }
  std::set<std::string> named_stalled;
  for (int i = 0; i < 3000 && !pipe.finished(); ++i) {
    std::this_thread::sleep_for(10ms);
    const auto beats = pipe.stage_heartbeats();
    for (std::size_t k = 0; k < ids.size(); ++k) watchdog.heartbeat(ids[k], beats[k].last);
    // Until the stall is over: at the end of a replay, streams that end first fall silent too.
    const std::int64_t stall_end = lidar.stall_end_ns.load();
    if (stall_end != 0 && drivers::host_now().ns > stall_end + 500'000'000) continue;
    for (const auto& s : watchdog.check(drivers::host_now()).stalled) named_stalled.insert(s.name);
  }
  ASSERT_TRUE(pipe.finished()) << "the replay did not end within 30 s";
  pipe.join();

  const std::int64_t begin = lidar.stall_begin_ns.load(), end = lidar.stall_end_ns.load();
  ASSERT_GT(begin, 0) << "the lidar never stalled";
  // The watchdog saw the wedged lidar stage, and only it.
  EXPECT_EQ(named_stalled, std::set<std::string>{"lidar_source"});
  std::lock_guard lock(m);
  // No optimised state while the lidar was stuck (after the scans already queued were done)...
  const auto in_stall = [&](const std::vector<std::int64_t>& v, std::int64_t from) {
    return std::count_if(v.begin(), v.end(), [&](std::int64_t t) { return t >= from && t < end; });
  };
  EXPECT_EQ(in_stall(pose_host_ns, begin + 1'000'000'000), 0);
  // ...yet odometry at the A9's 150 Hz through the whole 3 s.
  EXPECT_GT(in_stall(odom_host_ns, begin), 3 * 150 * 9 / 10);
  // The back end came back: optimised states after the stall.
  EXPECT_GT(std::count_if(pose_host_ns.begin(), pose_host_ns.end(),
                          [&](std::int64_t t) { return t >= end; }),
            5);
}

}  // namespace odometry_stall_replay_test
}  // namespace posed::testing
