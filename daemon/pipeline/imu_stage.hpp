#pragma once
// The IMU stage (one thread): Source -> decoder chosen by the channel's wire format -> ClockSync
// (device stamp -> host clock) -> the IMU queue to the fusion stage. Wire formats: the A9's
// serial frames, sensor_msgs/Imu from an imported ROS 1 bag (imu_stage_ros1.cpp), and Linux CAN
// frames decoded by imu.can_mapping (imu_stage_can.cpp).

#include <atomic>

#include "core/spsc_queue.hpp"
#include "core/sync/clock_sync.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/odometry_path.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "daemon/pipeline/wakeup.hpp"
#include "drivers/common/source.hpp"
#include "drivers/imu/a9_protocol.hpp"
#include "drivers/imu/can_imu_mapping.hpp"

namespace posed::pipeline {

class ImuStage {
 public:
  ImuStage(const config::PosedConfig& config, drivers::Source& source, SpscQueue<ImuItem>& queue,
           Wakeup& consumer, Heartbeat& heartbeat, StreamCounters& counters);
  /// Optional: odometry from every sample on this thread, right after it went to the queue.
  void set_odometry(OdometryPath* odometry) { odometry_ = odometry; }
  /// Optional: where each pushed sample's stamp goes (the D435i stage's failover reads it) [ns].
  void set_newest_stamp_out(std::atomic<std::int64_t>* out) { newest_stamp_out_ = out; }
  /// Runs until the Source ends (end of recording, or stopped), then forwards end-of-stream.
  void run();

 private:
  void on_a9_frame(const drivers::a9::A9Frame& frame, HostTime arrival);
  /// One serialized sensor_msgs/Imu (imu_stage_ros1.cpp).
  void on_ros1_imu(const drivers::RawChunk& chunk);
  /// One Linux struct can_frame/canfd_frame, decoded by imu.can_mapping (imu_stage_can.cpp).
  void on_can_frame(const drivers::RawChunk& chunk);
  void count_malformed_can(const char* what, std::size_t bytes);
  void push(const ImuSample& sample);
  void count_malformed();
  void publish_progress();

  const config::PosedConfig& config_;
  drivers::Source& source_;
  SpscQueue<ImuItem>& queue_;
  Wakeup& consumer_;
  Heartbeat& heartbeat_;
  StreamCounters& counters_;

  drivers::a9::A9Decoder a9_decoder_;
  drivers::can::CanImuDecoder can_decoder_;
  bool can_mapped_ = false;
  bool can_unmapped_said_ = false;
  bool can_clock_said_ = false;
  drivers::a9::A9Mounting mounting_;
  ClockSync clock_;
  std::uint64_t malformed_seen_ = 0;
  bool pushed_ = false;
  OdometryPath* odometry_ = nullptr;
  std::atomic<std::int64_t>* newest_stamp_out_ = nullptr;
  /// the Source's receive stamp of the chunk being decoded
  HostTime chunk_received_;
};

}  // namespace posed::pipeline
