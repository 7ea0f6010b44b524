#pragma once
// The lidar stage (one thread): Source -> Velodyne ScanBuilder (packet decoder, ClockSync from µs
// past the hour onto the host clock, scan assembler into pool buffers) -> the scan queue to the
// fusion stage. Position packets (channel 1) report the PPS state. Clouds imported from a ROS 1
// bag (sensor_msgs/PointCloud2) become scans directly (lidar_stage_ros1.cpp).

#include <memory>
#include <optional>

#include "core/payload_pool.hpp"
#include "core/spsc_queue.hpp"
#include "core/sync/clock_sync.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "daemon/pipeline/wakeup.hpp"
#include "drivers/common/source.hpp"
#include "drivers/recording/ros1_cloud_scan.hpp"
#include "drivers/velodyne/calibration.hpp"
#include "drivers/velodyne/scan_builder.hpp"

namespace posed::pipeline {

/// Scan figures beyond the stream's counters.
struct LidarScanCounters {
  std::atomic<std::uint64_t> scans{0};   ///< scans assembled
  std::atomic<std::uint64_t> points{0};  ///< points in those scans
  /// scans left out: stamped further from their arrival than kMaxScanStampToArrival (a corrupt
  /// device time the clock sync followed); counted as dropped too
  std::atomic<std::uint64_t> implausible{0};
  /// scans left out because the lidar fell silent while they were open: the first packet after
  /// the silence closes them, stamped the silence's length ago (stale, not corrupt; not dropped)
  std::atomic<std::uint64_t> cut_by_silence{0};
};

/// A scan's end stamp and the arrival of the packet that closed it are a few ms apart (the
/// transport, plus a lost last packet or two); a second means the stamp is wrong. Handed on, a
/// scan stamped in the future would hold the fusion stage's stamp-ordered merge of the lidar
/// for as long (every later scan waits behind it).
inline constexpr Duration kMaxScanStampToArrival = Duration::from_s(1);

class LidarStage {
 public:
  /// `calibration` empty: the manual's table for the model seen.
  LidarStage(const config::PosedConfig& config, drivers::velodyne::Calibration calibration,
             drivers::Source& source, SpscQueue<ScanItem>& queue, Wakeup& consumer,
             Heartbeat& heartbeat, StreamCounters& counters, LidarScanCounters& scan_counters);
  /// Runs until the Source ends, then flushes the scan in progress and forwards end-of-stream.
  void run();

  /// Pool buffers: the scans queued, the one being assembled and a few held by the fusion core.
  static std::size_t pool_buffers(const config::PosedConfig& config);
  /// Beam elevations of `calibration` (the VLP-32C's when empty), for clouds without rings [rad].
  static std::vector<double> ring_elevations(const drivers::velodyne::Calibration& calibration);

 private:
  void handle_position(const drivers::RawChunk& chunk);
  void handle_data(const drivers::RawChunk& chunk);
  /// One serialized sensor_msgs/PointCloud2 (lidar_stage_ros1.cpp).
  void handle_ros1_cloud(const drivers::RawChunk& chunk);
  void push_scan(LidarScan&& scan);
  /// Whether a scan stamped `stamp_to_arrival` from the packet that closed it is the one that was
  /// open when the lidar fell silent: its stamp is as old as the silence before that packet.
  bool cut_by_silence(Duration stamp_to_arrival) const;
  void forward_scans();

  const config::PosedConfig& config_;
  drivers::Source& source_;
  SpscQueue<ScanItem>& queue_;
  Wakeup& consumer_;
  Heartbeat& heartbeat_;
  StreamCounters& counters_;
  LidarScanCounters& scan_counters_;

  /// beam elevations by ring for clouds without a ring field [rad]; before builder_, which
  /// takes the calibration they come from
  std::vector<double> ring_elevations_rad_;
  PayloadPool pool_;
  drivers::velodyne::ScanBuilder builder_;
  std::unique_ptr<drivers::recording::ros1::CloudScanDecoder> cloud_decoder_;
  ClockSyncStatus cloud_clock_;
  bool reported_cloud_layout_ = false;
  drivers::velodyne::AssembledScan assembled_;
  /// the newest position packet said the PPS is locked
  bool pps_locked_ = false;
  /// the receive time of the position packet that first said the PPS was lost
  std::optional<HostTime> pps_lost_at_;
  /// the Source's receive stamp of the chunk being handled (a scan's is its last packet's)
  HostTime chunk_received_;
  /// the receive stamp of the data packet before the one being handled
  HostTime previous_data_received_;
  /// how long the lidar had been silent before the data packet being handled [s]
  Duration silence_before_;
};

}  // namespace posed::pipeline
