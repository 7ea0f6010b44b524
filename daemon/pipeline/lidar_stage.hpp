#pragma once
// The lidar stage (one thread): Source -> Velodyne ScanBuilder (packet decoder, ClockSync from µs
// past the hour onto the host clock, scan assembler into pool buffers) -> the scan queue to the
// fusion stage. Position packets (channel 1) report the PPS state.

#include <memory>

#include "core/payload_pool.hpp"
#include "core/spsc_queue.hpp"
#include "core/sync/clock_sync.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/stage_support.hpp"
#include "daemon/pipeline/wakeup.hpp"
#include "drivers/common/source.hpp"
#include "drivers/velodyne/calibration.hpp"
#include "drivers/velodyne/scan_builder.hpp"

namespace posed::pipeline {

/// Scan figures beyond the stream's counters.
struct LidarScanCounters {
  std::atomic<std::uint64_t> scans{0};   ///< scans assembled
  std::atomic<std::uint64_t> points{0};  ///< points in those scans
};

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

 private:
  void handle_position(const drivers::RawChunk& chunk);
  void handle_data(const drivers::RawChunk& chunk);
  void forward_scans();

  const config::PosedConfig& config_;
  drivers::Source& source_;
  SpscQueue<ScanItem>& queue_;
  Wakeup& consumer_;
  Heartbeat& heartbeat_;
  StreamCounters& counters_;
  LidarScanCounters& scan_counters_;

  PayloadPool pool_;
  drivers::velodyne::ScanBuilder builder_;
  drivers::velodyne::AssembledScan assembled_;
  bool reported_pps_ = false;
};

}  // namespace posed::pipeline
