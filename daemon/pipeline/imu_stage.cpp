#include "daemon/pipeline/imu_stage.hpp"

#include <string>

#include "daemon/pipeline/thread_policy.hpp"
#include "drivers/common/log.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::pipeline {

namespace a9 = drivers::a9;

namespace {
a9::A9Mounting mounting_from(const config::Rotation3& R) {
  a9::A9Mounting m;
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c) m.R_imu_sensor[r][c] = R[r * 3 + c];
  }
  return m;
}
}  // namespace

ImuStage::ImuStage(const config::PosedConfig& config, drivers::Source& source,
                   SpscQueue<ImuItem>& queue, Wakeup& consumer, Heartbeat& heartbeat,
                   StreamCounters& counters)
    : config_(config),
      source_(source),
      queue_(queue),
      consumer_(consumer),
      heartbeat_(heartbeat),
      counters_(counters),
      can_decoder_(config.imu.can_mapping),
      can_mapped_(!config.imu.can_mapping.fields.empty()),
      mounting_(mounting_from(config.imu.R_imu_sensor)),
      clock_(ClockSyncConfig{.kind = clock_kind_from(config.imu.clock_kind),
                             .nominal_rate_hz = config.imu.source == "synthetic"
                                                    ? config.synthetic_imu.rate_hz
                                                    : config.imu.rate_hz,
                             .latency = Duration::from_seconds(config.imu.clock_latency_s)}) {}

void ImuStage::on_a9_frame(const a9::A9Frame& frame, HostTime arrival) {
  if (frame.kind != a9::FrameKind::kSensor) return;
  const HostTime stamp = clock_.map_raw(frame.sensor.counter_us, arrival);
  log_clock_event("imu", clock_.last_event());
  // A counter the clock could not place (the first frames after a reboot, until they confirm
  // it): left out, counted by the clock, rather than stamped off the device's time line.
  if (clock_.last_event() == ClockEvent::kOutlier) return;
  const DeviceTime device_stamp = clock_.status().last_device_stamp;
  push(a9::to_imu_sample(frame.sensor, mounting_, stamp, device_stamp));
}

void ImuStage::push(const ImuSample& sample) {
  const PushResult r = queue_.push(ImuItem{sample, false, chunk_received_, counters_.bad()});
  if (r != PushResult::kPushed) counters_.dropped.fetch_add(1, std::memory_order_relaxed);
  counters_.decoded.fetch_add(1, std::memory_order_relaxed);
  pushed_ = true;
  if (newest_stamp_out_ != nullptr)
    newest_stamp_out_->store(sample.stamp.ns, std::memory_order_release);
  if (odometry_ != nullptr) odometry_->on_imu(sample, chunk_received_);
}

// Frames the decoder rejected since the last look (CRC, truncation, unknown kind).
void ImuStage::count_malformed() {
  const auto& c = a9_decoder_.counters();
  const std::uint64_t now_malformed = c.bad_crc + c.truncated + c.unknown_kind;
  if (now_malformed != malformed_seen_) {
    counters_.malformed.fetch_add(now_malformed - malformed_seen_, std::memory_order_relaxed);
  }
  malformed_seen_ = now_malformed;
}

void ImuStage::publish_progress() {
  if (!pushed_) return;
  pushed_ = false;
  consumer_.signal();
  counters_.publish_clock(clock_.status());
}

void ImuStage::run() {
  apply_thread_policy("posed-imu", config_.threads.imu_source);
  drivers::RawChunk chunk;
  SourceReader reader("imu", source_, heartbeat_, counters_);
  const auto on_frame = [&](const a9::A9Frame& frame) { on_a9_frame(frame, chunk.host_receive); };
  while (reader.next(chunk)) {
    chunk_received_ = chunk.host_receive;
    const std::string_view format = reader.wire_format(chunk);
    if (format == drivers::wire::kRos1Imu) {
      on_ros1_imu(chunk);
      publish_progress();
      continue;
    }
    if (format == drivers::wire::kCanFrame) {
      on_can_frame(chunk);
      publish_progress();
      continue;
    }
    if (format != drivers::wire::kA9Serial) {
      reader.undecodable(chunk);
      continue;
    }
    a9_decoder_.feed(
        std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(chunk.bytes.data()),
                                      chunk.bytes.size()),
        on_frame);
    count_malformed();
    publish_progress();
  }
  // End of stream: a partial frame left in the decoder is counted; frames hidden behind it kept.
  a9_decoder_.finish(on_frame);
  count_malformed();
  publish_progress();
  counters_.publish_clock(clock_.status());
  queue_.push(ImuItem{{}, true, {}});
  consumer_.signal();
}

}  // namespace posed::pipeline
