#pragma once
// The pipeline: Sources -> decoders -> clock sync -> queues -> fusion core -> outputs, one thread
// per stage (DESIGN.md, Data flow). The daemon and `posectl replay` build it with the same code;
// they differ only in the Sources passed in.
//
// Stop protocol: request_stop() stops the Sources; each stage forwards end-of-stream through its
// queue after what it already holds, so everything measured is processed and published (drain).
// The daemon aborts on a second signal instead of waiting.

#include <array>
#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/estimator/nav_state.hpp"
#include "core/measurements.hpp"
#include "core/spsc_queue.hpp"
#include "core/time.hpp"
#include "daemon/config/posed_config.hpp"
#include "daemon/pipeline/wakeup.hpp"
#include "drivers/common/source.hpp"

namespace posed::pipeline {

struct PipelineSources {
  /// bytes in the A9 wire format (live serial, synthetic, or replayed)
  std::unique_ptr<drivers::Source> imu;
  /// VLP-32C UDP payloads, channel 0 data, 1 position (live UDP, pcap, or replayed); optional
  std::unique_ptr<drivers::Source> lidar;
};

/// Per-stream figures for rt/posed/status and the exit summary.
struct StreamStatus {
  std::string name;
  double rate_hz = 0;           ///< decoded per second between status messages (publisher only)
  std::uint64_t received = 0;   ///< chunks read from the Source
  std::uint64_t decoded = 0;    ///< measurements decoded
  std::uint64_t dropped = 0;    ///< measurements dropped by the queue policy
  std::uint64_t malformed = 0;  ///< frames rejected by the decoder (CRC, truncation, unknown)
  std::int64_t clock_offset_ns = 0;  ///< host minus device time [ns]
  double clock_drift_ppm = 0;        ///< device clock rate error [ppm]
  double clock_jitter_ns = 0;        ///< spread of arrival delays [ns]
  double clock_uncertainty_ns = 0;   ///< 1-sigma of the mapped stamps [ns]
  std::string clock_state;           ///< converging | locked | lost
  std::string health;                ///< ok | no_data | degraded, with a reason
};

struct PipelineStatus {
  HostTime stamp;
  EstimatorMode mode = EstimatorMode::kAligning;
  std::vector<StreamStatus> streams;
  std::uint64_t lidar_scans = 0;        ///< scans assembled
  std::uint64_t lidar_points = 0;       ///< points in those scans
  std::uint64_t lidar_scans_fused = 0;  ///< scans the fusion core received
  std::uint64_t states = 0;             ///< states produced by the fusion core
  std::uint64_t states_dropped = 0;     ///< states dropped between fusion and publisher
};

/// Callbacks run on the publisher thread.
struct PipelineOutputs {
  /// every propagated state (the daemon publishes rt/posed/odom and, decimated, rt/posed/pose)
  std::function<void(const NavState&)> on_state;
  /// at publish.status_rate_hz, and once more at the end of the stream
  std::function<void(const PipelineStatus&)> on_status;
};

enum class Stage : std::uint8_t { kImuSource, kLidarSource, kFusion, kPublisher };
inline constexpr std::array<std::string_view, 4> kStageNames = {"imu_source", "lidar_source",
                                                                "fusion", "publisher"};

class Pipeline {
 public:
  Pipeline(const config::PosedConfig& config, PipelineSources sources, PipelineOutputs outputs);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Opens the Sources and starts the threads. A Source that cannot open yet (device absent) is
  /// logged and retried by its thread; only a configuration that cannot work returns false.
  bool start(std::string& error);
  /// Drain: Sources stop, queued data flows through, threads end. Safe from any thread.
  void request_stop();
  /// True once every stage thread has finished.
  bool finished() const { return finished_stages_.load() == active_stages().size(); }
  /// The stages this pipeline runs (the lidar stage only with a lidar Source).
  std::vector<Stage> active_stages() const;
  /// Joins the threads (call after finished() or request_stop()).
  void join();

  /// Last activity of each stage on the host clock, for the systemd watchdog.
  std::array<HostTime, kStageNames.size()> stage_heartbeats() const;
  /// A snapshot, safe from any thread.
  PipelineStatus status() const;

 private:
  struct ImuItem {
    ImuSample sample;
    bool end_of_stream = false;
  };
  struct ScanItem {
    LidarScan scan;
    bool end_of_stream = false;
  };
  struct StateItem {
    NavState state;
    bool end_of_stream = false;
  };
  struct Impl;

  void run_imu_source();
  void run_lidar_source();
  void run_fusion();
  void run_publisher();
  void beat(Stage stage);

  config::PosedConfig config_;
  PipelineSources sources_;
  PipelineOutputs outputs_;
  SpscQueue<ImuItem> imu_queue_;
  SpscQueue<ScanItem> scan_queue_;
  SpscQueue<StateItem> state_queue_;
  /// signalled by both source stages: the fusion core has input
  Wakeup fusion_ready_;
  Wakeup state_ready_;
  std::unique_ptr<Impl> impl_;
  std::array<std::atomic<std::int64_t>, kStageNames.size()> heartbeat_ns_{};
  std::atomic<std::size_t> finished_stages_{0};
  std::vector<std::thread> threads_;
};

}  // namespace posed::pipeline
