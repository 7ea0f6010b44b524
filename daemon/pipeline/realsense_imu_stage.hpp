#pragma once
// The D435i IMU stage (one thread): Source (IIO HID records, channel 0 accel, 1 gyro) ->
// RealsenseImuDecoder per channel -> RealsenseImuCombiner (one sample per gyro reading, in the
// IMU frame) -> ClockSync (the D435i's ns clock -> host) -> its own queue to the fusion stage,
// which uses the samples only while the A9 is silent (imu_failover.hpp). Live, it also carries
// rt/posed/odom through such a silence: it propagates its samples on the shared OdometryPath
// while the A9's newest stamp (published by the A9 stage) is older than failover_after_s.

#include <atomic>
#include <memory>
#include <optional>
#include <vector>

#include "core/spsc_queue.hpp"
#include "core/sync/clock_sync.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/imu_failover.hpp"
#include "daemon/pipeline/odometry_path.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "daemon/pipeline/wakeup.hpp"
#include "drivers/camera/realsense_imu_combiner.hpp"
#include "drivers/camera/realsense_imu_decoder.hpp"
#include "drivers/common/source.hpp"

namespace posed::pipeline {

/// The D435i IMU's mounting from the configuration: its axes and position in the IMU frame.
drivers::camera::RealsenseImuMounting realsense_imu_mounting(const config::PosedConfig& config);

class RealsenseImuStage {
 public:
  RealsenseImuStage(const config::PosedConfig& config, drivers::Source& source,
                    SpscQueue<ImuItem>& queue, Wakeup& consumer, Heartbeat& heartbeat,
                    StreamCounters& counters);
  /// Live: rt/posed/odom from this IMU while the A9's newest stamp (`a9_newest_ns`, the A9
  /// stage's) is older than failover_after_s.
  void set_odometry(OdometryPath* odometry, const std::atomic<std::int64_t>* a9_newest_ns) {
    odometry_ = odometry;
    a9_newest_ns_ = a9_newest_ns;
  }
  /// Runs until the Source ends, then forwards end-of-stream.
  void run();

 private:
  void on_chunk(const drivers::RawChunk& chunk, std::string_view wire_format);
  void push(const drivers::camera::RealsenseImuSample& sample);

  const config::PosedConfig& config_;
  drivers::Source& source_;
  SpscQueue<ImuItem>& queue_;
  Wakeup& consumer_;
  Heartbeat& heartbeat_;
  StreamCounters& counters_;
  /// per channel (0 accel, 1 gyro), made from the channel's wire format on its first chunk
  std::optional<drivers::camera::RealsenseImuDecoder> decoders_[2];
  std::uint64_t partial_seen_[2] = {0, 0};
  drivers::camera::RealsenseImuCombiner combiner_;
  ClockSync clock_;
  std::vector<drivers::camera::D4xxMotionSample> readings_;
  std::vector<drivers::camera::RealsenseImuSample> combined_;
  bool pushed_ = false;
  OdometryPath* odometry_ = nullptr;
  const std::atomic<std::int64_t>* a9_newest_ns_ = nullptr;
  ImuFailover odometry_failover_;
  HostTime chunk_received_;
};

}  // namespace posed::pipeline
