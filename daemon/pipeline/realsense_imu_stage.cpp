#include "daemon/pipeline/realsense_imu_stage.hpp"

#include <string>

#include "daemon/pipeline/estimator_config.hpp"
#include "daemon/pipeline/thread_policy.hpp"
#include "drivers/common/log.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::pipeline {

namespace cam = drivers::camera;

cam::RealsenseImuMounting realsense_imu_mounting(const config::PosedConfig& config) {
  const Eigen::Isometry3d T_imu_rsimu = to_isometry(config.extrinsics.T_imu_cam) *
                                        to_isometry(config.extrinsics.T_cam_depth) *
                                        to_isometry(config.extrinsics.T_depth_rsimu);
  cam::RealsenseImuMounting m;
  m.R_imu_depth = T_imu_rsimu.linear();
  m.p_imu_rsimu_m = T_imu_rsimu.translation();
  return m;
}

RealsenseImuStage::RealsenseImuStage(const config::PosedConfig& config, drivers::Source& source,
                                     SpscQueue<ImuItem>& queue, Wakeup& consumer,
                                     Heartbeat& heartbeat, StreamCounters& counters)
    : config_(config),
      source_(source),
      queue_(queue),
      consumer_(consumer),
      heartbeat_(heartbeat),
      counters_(counters),
      combiner_(realsense_imu_mounting(config)),
      clock_(
          ClockSyncConfig{.kind = DeviceClockKind::kHardwareNs,
                          .nominal_rate_hz = config.realsense_imu.gyro_rate_hz,
                          .latency = Duration::from_seconds(config.realsense_imu.clock_latency_s)}),
      odometry_failover_(Duration::from_seconds(config.realsense_imu.failover_after_s)) {
  readings_.resize(64);
  combined_.reserve(64);
}

void RealsenseImuStage::push(const cam::RealsenseImuSample& s) {
  const HostTime stamp = clock_.map_raw(static_cast<std::uint64_t>(s.device_stamp.ns), s.arrival);
  log_clock_event("realsense_imu", clock_.last_event());
  if (clock_.last_event() == ClockEvent::kOutlier) return;
  ImuSample sample;
  sample.stamp = stamp;
  sample.device_stamp = clock_.status().last_device_stamp;
  sample.angular_velocity_radps = s.angular_velocity_radps;
  sample.specific_force_mps2 = s.specific_force_mps2;
  sample.from_backup_imu = true;
  const PushResult r = queue_.push(ImuItem{sample, false, s.arrival, counters_.bad()});
  if (r != PushResult::kPushed) counters_.dropped.fetch_add(1, std::memory_order_relaxed);
  counters_.decoded.fetch_add(1, std::memory_order_relaxed);
  pushed_ = true;
  if (odometry_ != nullptr && a9_newest_ns_ != nullptr) {
    const std::int64_t a9 = a9_newest_ns_->load(std::memory_order_acquire);
    if (a9 != 0) odometry_failover_.saw_primary(HostTime::from_ns(a9));
    if (odometry_failover_.take_backup(stamp)) odometry_->on_imu(sample, s.arrival);
  }
}

void RealsenseImuStage::on_chunk(const drivers::RawChunk& chunk, std::string_view wire_format) {
  const std::uint32_t channel = chunk.channel;
  auto& decoder = decoders_[channel];
  if (!decoder) {
    decoder.emplace(wire_format);
    if (!decoder->valid()) {
      POSED_LOG_WARN("realsense_imu: channel %u: %s: its records are not decoded", channel,
                     decoder->error().c_str());
    }
  }
  std::span<const std::byte> bytes(chunk.bytes.data(), chunk.bytes.size());
  const std::uint64_t bad_before = decoder->counters().bad_chunks;
  while (!bytes.empty()) {
    const std::size_t record = std::max<std::size_t>(decoder->record_bytes(), 1);
    const std::size_t take = std::min(bytes.size(), readings_.size() * record);
    const std::size_t n = decoder->decode(bytes.first(take), readings_);
    combined_.clear();
    for (std::size_t i = 0; i < n; ++i) combiner_.add(readings_[i], chunk.host_receive, combined_);
    for (const auto& s : combined_) push(s);
    bytes = bytes.subspan(take);
    if (!decoder->valid()) break;
  }
  const auto& c = decoder->counters();
  const std::uint64_t bad =
      (c.bad_chunks - bad_before) + (c.partial_bytes - partial_seen_[channel]);
  partial_seen_[channel] = c.partial_bytes;
  if (bad > 0) counters_.malformed.fetch_add(1, std::memory_order_relaxed);
}

void RealsenseImuStage::run() {
  apply_thread_policy("posed-rsimu", config_.threads.imu_source);
  drivers::RawChunk chunk;
  SourceReader reader("realsense_imu", source_, heartbeat_, counters_);
  while (reader.next(chunk)) {
    const std::string_view format = reader.wire_format(chunk);
    const bool iio =
        format.substr(0, drivers::wire::kIioAccel3d.size()) == drivers::wire::kIioAccel3d ||
        format.substr(0, drivers::wire::kIioGyro3d.size()) == drivers::wire::kIioGyro3d;
    if (!iio || chunk.channel > 1) {
      reader.undecodable(chunk);
      continue;
    }
    on_chunk(chunk, format);
    if (pushed_) {
      pushed_ = false;
      consumer_.signal();
      counters_.publish_clock(clock_.status());
    }
  }
  counters_.publish_clock(clock_.status());
  queue_.push(ImuItem{{}, true, {}});
  consumer_.signal();
}

}  // namespace posed::pipeline
