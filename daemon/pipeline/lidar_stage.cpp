#include "daemon/pipeline/lidar_stage.hpp"

#include "core/sync/measurement_gate.hpp"
#include "daemon/pipeline/thread_policy.hpp"
#include "drivers/common/log.hpp"
#include "drivers/common/wire_format.hpp"

namespace posed::pipeline {

namespace velodyne = drivers::velodyne;

std::vector<double> LidarStage::ring_elevations(const velodyne::Calibration& calibration) {
  // Without a calibration file the rig's sensor, the VLP-32C, as its manual tables it.
  const velodyne::Calibration c = calibration.lasers.empty()
                                      ? velodyne::builtin_calibration(velodyne::ProductId::kVlp32c)
                                      : calibration;
  std::vector<double> out;
  for (const auto& laser : c.lasers) out.push_back(laser.vert_correction_rad);
  return out;
}

std::size_t LidarStage::pool_buffers(const config::PosedConfig& config) {
  // The queue, the estimator's gate, the fusion stage's look-ahead, the scan being assembled,
  // and one to spare: however the others fill, the next scan has a buffer.
  return static_cast<std::size_t>(config.queues.scan_capacity) + kLidarScanGateCapacity + 3;
}

LidarStage::LidarStage(const config::PosedConfig& config, velodyne::Calibration calibration,
                       drivers::Source& source, SpscQueue<ScanItem>& queue, Wakeup& consumer,
                       Heartbeat& heartbeat, StreamCounters& counters,
                       LidarScanCounters& scan_counters)
    : config_(config),
      source_(source),
      queue_(queue),
      consumer_(consumer),
      heartbeat_(heartbeat),
      counters_(counters),
      scan_counters_(scan_counters),
      ring_elevations_rad_(ring_elevations(calibration)),
      pool_(pool_buffers(config),
            velodyne::max_points_per_scan(config.lidar.rpm) * sizeof(LidarPoint)),
      builder_(std::move(calibration),
               velodyne::ScanBuilderConfig{
                   .decoder = {.min_range_m = config.lidar.min_range_m,
                               .max_range_m = config.lidar.max_range_m},
                   .clock = {.kind = clock_kind_from(config.lidar.clock_kind),
                             .nominal_rate_hz = 1507.0,
                             .latency = Duration::from_seconds(config.lidar.clock_latency_s)},
                   .assembler = {.cut_azimuth_cdeg = static_cast<std::uint32_t>(
                                     config.lidar.cut_azimuth_deg * 100)}},
               pool_) {}

bool LidarStage::cut_by_silence(Duration stamp_to_arrival) const {
  // The scan ended before the silence, give or take the few ms a scan's stamp and its closing
  // packet's arrival are apart.
  return silence_before_ > kMaxScanStampToArrival && stamp_to_arrival < Duration() &&
         -stamp_to_arrival <= silence_before_ + kMaxScanStampToArrival;
}

void LidarStage::push_scan(LidarScan&& scan) {
  const Duration off = scan.end_stamp - chunk_received_;
  if (chunk_received_.ns != 0 && cut_by_silence(off)) {
    // By the time the data came back the estimate has gone on from the IMU: the scan is stale,
    // not corrupt, and the stream is not degraded for it.
    scan_counters_.cut_by_silence.fetch_add(1, std::memory_order_relaxed);
    POSED_LOG_INFO("lidar: the scan in progress when the data stopped %.2f s ago is left out",
                   -off.seconds());
    return;
  }
  if (chunk_received_.ns != 0 && (off > kMaxScanStampToArrival || off < -kMaxScanStampToArrival)) {
    if (scan_counters_.implausible.fetch_add(1, std::memory_order_relaxed) == 0) {
      POSED_LOG_WARN(
          "lidar: scan stamped %.3f s from its arrival left out (a corrupt device "
          "time?); such scans are counted as dropped",
          off.seconds());
    }
    counters_.dropped.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  scan_counters_.scans.fetch_add(1, std::memory_order_relaxed);
  scan_counters_.points.fetch_add(scan.point_count, std::memory_order_relaxed);
  const PushResult r =
      queue_.push(ScanItem{std::move(scan), false, chunk_received_, counters_.bad()});
  if (r == PushResult::kRejectedFull || r == PushResult::kRejectedTimeout ||
      r == PushResult::kPushedDropped) {
    counters_.dropped.fetch_add(1, std::memory_order_relaxed);
  }
}

void LidarStage::forward_scans() {
  bool pushed = false;
  while (builder_.pop(assembled_)) {
    push_scan(std::move(assembled_.scan));
    pushed = true;
  }
  if (pushed) consumer_.signal();
}

void LidarStage::handle_position(const drivers::RawChunk& chunk) {
  // The PPS state says whether the µs-past-the-hour is GPS-aligned. Without PPS the lidar's
  // clock free-runs on its crystal and steps back when it re-locks; the clock sync follows both,
  // the log says when.
  const auto pps = builder_.add_position(chunk.bytes);
  if (!pps) return;
  const bool locked = *pps == velodyne::PpsStatus::kLocked;
  if (locked && !pps_locked_) {
    if (pps_lost_at_) {
      POSED_LOG_INFO("lidar: PPS locked again after %.1f s, device time is GPS-aligned",
                     (chunk.host_receive - *pps_lost_at_).seconds());
    } else {
      POSED_LOG_INFO("lidar: PPS locked, device time is GPS-aligned");
    }
  } else if (!locked && pps_locked_) {
    POSED_LOG_WARN("lidar: PPS lost (status %s), device time free-runs until it re-locks",
                   std::string(velodyne::to_string(*pps)).c_str());
    pps_lost_at_ = chunk.host_receive;
  }
  pps_locked_ = locked;
}

void LidarStage::handle_data(const drivers::RawChunk& chunk) {
  silence_before_ =
      previous_data_received_.ns != 0 ? chunk.host_receive - previous_data_received_ : Duration();
  previous_data_received_ = chunk.host_receive;
  if (builder_.add_data(chunk.bytes, chunk.host_receive) != velodyne::DecodeStatus::kOk) {
    counters_.malformed.store(builder_.decoder().counters().malformed(), std::memory_order_relaxed);
    return;
  }
  const std::uint64_t decoded = counters_.decoded.fetch_add(1, std::memory_order_relaxed) + 1;
  log_clock_event("lidar", builder_.clock().last_event());
  forward_scans();
  if (decoded % 64 == 0) counters_.publish_clock(builder_.clock().status());
}

void LidarStage::run() {
  apply_thread_policy("posed-lidar", config_.threads.lidar_source);
  drivers::RawChunk chunk;
  SourceReader reader("lidar", source_, heartbeat_, counters_);
  while (reader.next(chunk)) {
    chunk_received_ = chunk.host_receive;
    const std::string_view format = reader.wire_format(chunk);
    if (format == drivers::wire::kVelodyneData) {
      handle_data(chunk);
    } else if (format == drivers::wire::kVelodynePosition) {
      handle_position(chunk);
    } else if (format == drivers::wire::kRos1PointCloud2) {
      handle_ros1_cloud(chunk);
    } else {
      reader.undecodable(chunk);
    }
  }
  builder_.flush();
  forward_scans();
  counters_.publish_clock(cloud_decoder_ ? cloud_clock_ : builder_.clock().status());
  queue_.push(ScanItem{{}, true, {}});
  consumer_.signal();
}

}  // namespace posed::pipeline
