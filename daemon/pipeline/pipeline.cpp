#include "daemon/pipeline/pipeline.hpp"

#include <chrono>
#include <cmath>
#include <mutex>

#include "core/estimator/strapdown.hpp"
#include "core/sync/clock_sync.hpp"
#include "daemon/pipeline/thread_policy.hpp"
#include "drivers/common/host_clock.hpp"
#include "drivers/common/log.hpp"
#include "drivers/imu/a9_protocol.hpp"
#include "drivers/velodyne/calibration_loader.hpp"
#include "drivers/velodyne/packet_decoder.hpp"
#include "drivers/velodyne/position_packet.hpp"
#include "drivers/velodyne/scan_assembler.hpp"

namespace posed::pipeline {

namespace a9 = drivers::a9;
namespace velodyne = drivers::velodyne;

namespace {
constexpr auto kWaitTimeout = std::chrono::milliseconds(50);
const Duration kReadTimeout = Duration::from_ms(100);

// The schema admits only these names (config_schema.cpp), so the last branch is "none".
DeviceClockKind clock_kind_from(const std::string& name) {
  if (name == "counter_us_32bit") return DeviceClockKind::kCounterUs32Bit;
  if (name == "us_past_hour") return DeviceClockKind::kUsPastHour;
  if (name == "hardware_ns") return DeviceClockKind::kHardwareNs;
  return DeviceClockKind::kNone;
}

DropPolicy queue_policy(const std::unique_ptr<drivers::Source>& source) {
  return source && !source->live() ? DropPolicy::kBlockWithTimeout : DropPolicy::kDropOldest;
}

// Copies a stream's clock figures; returns whether the stream is stale. Silence for a second
// means lost, whatever the estimate said last; only for live Sources, whose arrival times are on
// this host's clock (a replay's are the recording's).
bool fill_clock(StreamStatus& out, const ClockSyncStatus& clock, HostTime now, bool live) {
  out.clock_offset_ns = clock.offset.ns;
  out.clock_drift_ppm = clock.drift_ppm;
  out.clock_jitter_ns = static_cast<double>(clock.jitter.ns);
  out.clock_uncertainty_ns = static_cast<double>(clock.uncertainty.ns);
  const bool stale = clock.samples == 0 || (live && now - clock.last_arrival > Duration::from_s(1));
  out.clock_state =
      std::string(to_string(stale && clock.samples > 0 ? SyncState::kLost : clock.state));
  return stale;
}

std::string health_of(bool device_lost, const StreamStatus& s, bool stale) {
  if (device_lost) return "device_lost";
  if (s.decoded == 0 || stale) return "no_data";
  if (s.malformed > 0 || s.dropped > 0) return "degraded";
  return "ok";
}

// Dual return at 3014 packets/s of 384 points, for one rotation at `rpm`, with 20 % margin for a
// slow rotation or a late cut.
std::size_t max_points_per_scan(double rpm) {
  return static_cast<std::size_t>(1.2 * 3014.0 * 384.0 * 60.0 / rpm);
}

a9::A9Mounting mounting_from(const config::Rotation3& R) {
  a9::A9Mounting m;
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c) m.R_imu_sensor[r][c] = R[r * 3 + c];
  }
  return m;
}
}  // namespace

// State owned by one stage thread each; what other threads read goes through atomics or the
// snapshot mutex.
struct Pipeline::Impl {
  // imu_source thread
  a9::A9Decoder decoder;
  ClockSync imu_clock;
  a9::A9Mounting mounting;
  // lidar_source thread
  velodyne::PacketDecoder lidar_decoder;
  ClockSync lidar_clock;
  PayloadPool scan_pool;
  velodyne::ScanAssembler assembler;
  /// heap, not stack: 384 decoded points
  std::unique_ptr<velodyne::DecodedPacket> packet = std::make_unique<velodyne::DecodedPacket>();
  // fusion thread
  Strapdown strapdown;

  // shared, for status()
  std::atomic<std::uint64_t> imu_received{0};
  std::atomic<std::uint64_t> imu_decoded{0};
  std::atomic<std::uint64_t> imu_malformed{0};
  std::atomic<std::uint64_t> states{0};
  std::atomic<EstimatorMode> mode{EstimatorMode::kAligning};
  std::atomic<bool> imu_lost{false};
  std::atomic<std::uint64_t> lidar_received{0};
  std::atomic<std::uint64_t> lidar_decoded{0};
  std::atomic<std::uint64_t> lidar_malformed{0};
  std::atomic<std::uint64_t> lidar_scans{0};
  std::atomic<std::uint64_t> lidar_points{0};
  std::atomic<std::uint64_t> lidar_scans_dropped{0};
  std::atomic<std::uint64_t> lidar_scans_fused{0};
  std::atomic<bool> lidar_lost{false};
  mutable std::mutex snapshot_mutex;
  ClockSyncStatus imu_clock_status;    // guarded by snapshot_mutex
  ClockSyncStatus lidar_clock_status;  // guarded by snapshot_mutex

  Impl(const config::PosedConfig& c, velodyne::Calibration lidar_calibration)
      : imu_clock(ClockSyncConfig{.kind = clock_kind_from(c.imu.clock_kind),
                                  .nominal_rate_hz = c.imu.source == "synthetic"
                                                         ? c.synthetic_imu.rate_hz
                                                         : c.imu.rate_hz,
                                  .latency = Duration::from_seconds(c.imu.clock_latency_s)}),
        mounting(mounting_from(c.imu.R_imu_sensor)),
        lidar_decoder(lidar_calibration,
                      velodyne::DecoderConfig{.min_range_m = c.lidar.min_range_m,
                                              .max_range_m = c.lidar.max_range_m}),
        lidar_clock(ClockSyncConfig{.kind = clock_kind_from(c.lidar.clock_kind),
                                    .nominal_rate_hz = 1507.0,
                                    .latency = Duration::from_seconds(c.lidar.clock_latency_s)}),
        // Room for the scans queued, plus the one being assembled and a few in the fusion core.
        scan_pool(static_cast<std::size_t>(c.queues.scan_capacity) + 4,
                  max_points_per_scan(c.lidar.rpm) * sizeof(LidarPoint)),
        assembler(scan_pool,
                  velodyne::ScanAssemblerConfig{.cut_azimuth_cdeg = static_cast<std::uint32_t>(
                                                    c.lidar.cut_azimuth_deg * 100)}),
        strapdown(StrapdownConfig{
            .gravity_mps2 = c.imu.gravity_mps2,
            .init_static = Duration::from_seconds(c.estimator.init_static_s),
            .init_max_gyro_radps = c.estimator.init_max_gyro_radps,
            .gyro_noise_density = c.imu.gyro_noise_density,
            .accel_noise_density = c.imu.accel_noise_density,
        }) {}
};

Pipeline::Pipeline(const config::PosedConfig& config, PipelineSources sources,
                   PipelineOutputs outputs)
    : config_(config),
      sources_(std::move(sources)),
      outputs_(std::move(outputs)),
      // Live sensors: a stalled consumer must not make us process stale data later. Recordings
      // and generators: nothing may be lost, so the producer waits (deterministic replays).
      imu_queue_(static_cast<std::size_t>(config.queues.imu_capacity), queue_policy(sources_.imu),
                 std::chrono::seconds(1)),
      scan_queue_(static_cast<std::size_t>(config.queues.scan_capacity),
                  queue_policy(sources_.lidar), std::chrono::seconds(1)),
      state_queue_(static_cast<std::size_t>(config.queues.state_capacity),
                   queue_policy(sources_.imu), std::chrono::seconds(1)) {}

Pipeline::~Pipeline() {
  request_stop();
  join();
}

std::vector<Stage> Pipeline::active_stages() const {
  std::vector<Stage> stages = {Stage::kImuSource, Stage::kFusion, Stage::kPublisher};
  if (sources_.lidar) stages.push_back(Stage::kLidarSource);
  return stages;
}

bool Pipeline::start(std::string& error) {
  if (!sources_.imu) {
    error = "no IMU source configured";
    return false;
  }
  velodyne::Calibration calibration;  // empty: the manual's table for the model seen
  if (sources_.lidar && !config_.lidar.calibration.empty() &&
      !velodyne::load_calibration(config_.lidar.calibration, calibration, error)) {
    return false;
  }
  impl_ = std::make_unique<Impl>(config_, std::move(calibration));
  if (sources_.lidar) {
    std::string lidar_error;
    if (!sources_.lidar->open(lidar_error)) {
      POSED_LOG_WARN("lidar source not open yet: %s; retrying in the background",
                     lidar_error.c_str());
    }
  }
  std::string open_error;
  if (!sources_.imu->open(open_error)) {
    // The device may appear later (USB enumeration, cable): the Source retries on read().
    POSED_LOG_WARN("IMU source not open yet: %s; retrying in the background", open_error.c_str());
  }
  const std::int64_t now = drivers::host_now().ns;
  for (auto& h : heartbeat_ns_) h.store(now);
  threads_.emplace_back([this] { run_imu_source(); });
  if (sources_.lidar) threads_.emplace_back([this] { run_lidar_source(); });
  threads_.emplace_back([this] { run_fusion(); });
  threads_.emplace_back([this] { run_publisher(); });
  return true;
}

void Pipeline::request_stop() {
  if (sources_.imu) sources_.imu->request_stop();
  if (sources_.lidar) sources_.lidar->request_stop();
}

void Pipeline::join() {
  for (auto& t : threads_) {
    if (t.joinable()) t.join();
  }
  threads_.clear();
}

void Pipeline::beat(Stage stage) {
  heartbeat_ns_[static_cast<std::size_t>(stage)].store(drivers::host_now().ns,
                                                       std::memory_order_relaxed);
}

std::array<HostTime, kStageNames.size()> Pipeline::stage_heartbeats() const {
  std::array<HostTime, kStageNames.size()> out;
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = HostTime::from_ns(heartbeat_ns_[i].load(std::memory_order_relaxed));
  }
  return out;
}

void Pipeline::run_imu_source() {
  apply_thread_policy("posed-imu", config_.threads.imu_source);
  Impl& s = *impl_;
  drivers::Source& source = *sources_.imu;
  drivers::RawChunk chunk;
  bool reported_lost = false;
  std::uint64_t malformed_seen = 0;
  bool pushed = false;

  const auto on_frame = [&](const a9::A9Frame& frame) {
    if (frame.kind != a9::FrameKind::kSensor) return;
    const HostTime stamp = s.imu_clock.map_raw(frame.sensor.counter_us, chunk.host_receive);
    if (const ClockEvent e = s.imu_clock.last_event(); e != ClockEvent::kNone) {
      const bool bad = e == ClockEvent::kReset || e == ClockEvent::kJump || e == ClockEvent::kLost;
      log::write(bad ? log::Level::kWarning : log::Level::kInfo, "imu clock: %.*s",
                 static_cast<int>(to_string(e).size()), to_string(e).data());
    }
    const DeviceTime device_stamp = s.imu_clock.status().last_device_stamp;
    imu_queue_.push(
        ImuItem{a9::to_imu_sample(frame.sensor, s.mounting, stamp, device_stamp), false});
    s.imu_decoded.fetch_add(1, std::memory_order_relaxed);
    pushed = true;
  };
  // Frames the decoder rejected since the last look (CRC, truncation, unknown kind).
  const auto count_malformed = [&] {
    const auto& c = s.decoder.counters();
    const std::uint64_t now_malformed = c.bad_crc + c.truncated + c.unknown_kind;
    if (now_malformed != malformed_seen) s.imu_malformed.fetch_add(now_malformed - malformed_seen);
    malformed_seen = now_malformed;
  };
  const auto publish_progress = [&] {
    if (!pushed) return;
    pushed = false;
    fusion_ready_.signal();
    std::lock_guard lock(s.snapshot_mutex);
    s.imu_clock_status = s.imu_clock.status();
  };

  for (;;) {
    beat(Stage::kImuSource);
    const drivers::ReadStatus rs = source.read(chunk, kReadTimeout);
    if (rs == drivers::ReadStatus::kEndOfStream) break;
    if (rs == drivers::ReadStatus::kDeviceLost) {
      if (!reported_lost) POSED_LOG_WARN("IMU device lost; waiting for it to come back");
      reported_lost = true;
      s.imu_lost.store(true);
      continue;
    }
    if (rs != drivers::ReadStatus::kData) continue;
    if (reported_lost) POSED_LOG_NOTICE("IMU device back");
    reported_lost = false;
    s.imu_lost.store(false);
    s.imu_received.fetch_add(1, std::memory_order_relaxed);

    s.decoder.feed(
        std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(chunk.bytes.data()),
                                      chunk.bytes.size()),
        on_frame);
    count_malformed();
    publish_progress();
  }
  // End of stream: a partial frame left in the decoder is counted; frames hidden behind it kept.
  s.decoder.finish(on_frame);
  count_malformed();
  publish_progress();
  imu_queue_.push(ImuItem{{}, true});
  fusion_ready_.signal();
  finished_stages_.fetch_add(1);
}

void Pipeline::run_lidar_source() {
  apply_thread_policy("posed-lidar", config_.threads.lidar_source);
  Impl& s = *impl_;
  drivers::Source& source = *sources_.lidar;
  drivers::RawChunk chunk;
  bool reported_lost = false;
  bool reported_pps = false;
  velodyne::AssembledScan assembled;

  const auto forward_scans = [&] {
    bool pushed = false;
    while (s.assembler.pop(assembled)) {
      s.lidar_scans.fetch_add(1, std::memory_order_relaxed);
      s.lidar_points.fetch_add(assembled.scan.point_count, std::memory_order_relaxed);
      const PushResult r = scan_queue_.push(ScanItem{std::move(assembled.scan), false});
      if (r == PushResult::kRejectedFull || r == PushResult::kRejectedTimeout) {
        s.lidar_scans_dropped.fetch_add(1, std::memory_order_relaxed);
      }
      pushed = true;
    }
    if (pushed) fusion_ready_.signal();
  };

  for (;;) {
    beat(Stage::kLidarSource);
    const drivers::ReadStatus rs = source.read(chunk, kReadTimeout);
    if (rs == drivers::ReadStatus::kEndOfStream) break;
    if (rs == drivers::ReadStatus::kDeviceLost) {
      if (!reported_lost) POSED_LOG_WARN("lidar lost; waiting for it to come back");
      reported_lost = true;
      s.lidar_lost.store(true);
      continue;
    }
    if (rs != drivers::ReadStatus::kData) continue;
    reported_lost = false;
    s.lidar_lost.store(false);
    s.lidar_received.fetch_add(1, std::memory_order_relaxed);

    if (chunk.channel == 1) {
      // Position packets: the PPS state says whether the µs-past-the-hour is GPS-aligned.
      velodyne::PositionPacket position;
      if (velodyne::parse_position_packet(chunk.bytes, position) !=
              velodyne::PositionStatus::kWrongSize &&
          position.pps == velodyne::PpsStatus::kLocked && !reported_pps) {
        POSED_LOG_INFO("lidar: PPS locked, device time is GPS-aligned");
        reported_pps = true;
      }
      continue;
    }
    if (s.lidar_decoder.decode(chunk.bytes, *s.packet) != velodyne::DecodeStatus::kOk) {
      s.lidar_malformed.store(s.lidar_decoder.counters().malformed(), std::memory_order_relaxed);
      continue;
    }
    s.lidar_decoded.fetch_add(1, std::memory_order_relaxed);
    const HostTime stamp = s.lidar_clock.map_raw(s.packet->device_time_us, chunk.host_receive);
    if (const ClockEvent e = s.lidar_clock.last_event(); e != ClockEvent::kNone) {
      const bool bad = e == ClockEvent::kReset || e == ClockEvent::kJump || e == ClockEvent::kLost;
      log::write(bad ? log::Level::kWarning : log::Level::kInfo, "lidar clock: %.*s",
                 static_cast<int>(to_string(e).size()), to_string(e).data());
    }
    const DeviceTime device_stamp = s.lidar_clock.status().last_device_stamp;
    // The assembler stamps points as device time + this offset: ClockSync's mapping, per packet.
    s.assembler.set_host_minus_device(stamp - HostTime::from_ns(device_stamp.ns));
    s.assembler.add(*s.packet, device_stamp);
    forward_scans();
    if (s.lidar_decoded.load(std::memory_order_relaxed) % 64 == 0) {
      std::lock_guard lock(s.snapshot_mutex);
      s.lidar_clock_status = s.lidar_clock.status();
    }
  }
  s.assembler.flush();
  forward_scans();
  {
    std::lock_guard lock(s.snapshot_mutex);
    s.lidar_clock_status = s.lidar_clock.status();
  }
  scan_queue_.push(ScanItem{{}, true});
  fusion_ready_.signal();
  finished_stages_.fetch_add(1);
}

void Pipeline::run_fusion() {
  apply_thread_policy("posed-fusion", config_.threads.fusion);
  Impl& s = *impl_;
  bool imu_done = false;
  bool lidar_done = !sources_.lidar;
  while (!imu_done || !lidar_done) {
    beat(Stage::kFusion);
    fusion_ready_.wait_for(kWaitTimeout);
    // Scans are counted and their buffers returned: the strapdown estimator has no use for them;
    // the lidar-inertial estimator will consume them here.
    ScanItem scan;
    while (!lidar_done && scan_queue_.try_pop(scan)) {
      if (scan.end_of_stream) {
        lidar_done = true;
        break;
      }
      s.lidar_scans_fused.fetch_add(1, std::memory_order_relaxed);
    }
    ImuItem item;
    bool produced = false;
    while (!imu_done && imu_queue_.try_pop(item)) {
      if (item.end_of_stream) {
        imu_done = true;
        break;
      }
      if (auto state = s.strapdown.add(item.sample)) {
        state_queue_.push(StateItem{*state, false});
        s.states.fetch_add(1, std::memory_order_relaxed);
        produced = true;
      }
      s.mode.store(s.strapdown.mode(), std::memory_order_relaxed);
    }
    if (produced) state_ready_.signal();
  }
  state_queue_.push(StateItem{{}, true});
  state_ready_.signal();
  finished_stages_.fetch_add(1);
}

void Pipeline::run_publisher() {
  apply_thread_policy("posed-publish", config_.threads.publisher);
  const Duration status_period = Duration::from_seconds(1.0 / config_.publish.status_rate_hz);
  HostTime next_status = drivers::host_now() + status_period;
  PipelineStatus previous;
  bool done = false;
  while (!done) {
    beat(Stage::kPublisher);
    state_ready_.wait_for(kWaitTimeout);
    StateItem item;
    while (state_queue_.try_pop(item)) {
      if (item.end_of_stream) {
        done = true;
        break;
      }
      if (outputs_.on_state) outputs_.on_state(item.state);
    }
    const HostTime now = drivers::host_now();
    if (done || now >= next_status) {
      next_status = now + status_period;
      PipelineStatus st = status();
      // Rates from the difference to the previous snapshot, which only this thread keeps.
      if (previous.stamp.ns != 0 && st.stamp > previous.stamp) {
        const double dt = (st.stamp - previous.stamp).seconds();
        for (std::size_t i = 0; i < st.streams.size() && i < previous.streams.size(); ++i) {
          st.streams[i].rate_hz =
              static_cast<double>(st.streams[i].decoded - previous.streams[i].decoded) / dt;
        }
      }
      previous = st;
      if (outputs_.on_status) outputs_.on_status(st);
    }
  }
  finished_stages_.fetch_add(1);
}

PipelineStatus Pipeline::status() const {
  if (!impl_) return {};  // not started
  const Impl& s = *impl_;
  const HostTime now = drivers::host_now();
  PipelineStatus st;
  st.stamp = now;
  st.mode = s.mode.load();
  st.states = s.states.load();
  st.states_dropped = state_queue_.counters().dropped();

  StreamStatus imu;
  imu.name = "imu";
  imu.received = s.imu_received.load();
  imu.decoded = s.imu_decoded.load();
  imu.malformed = s.imu_malformed.load();
  imu.dropped = imu_queue_.counters().dropped();
  ClockSyncStatus clock;
  {
    std::lock_guard lock(s.snapshot_mutex);
    clock = s.imu_clock_status;
  }
  const bool imu_stale = fill_clock(imu, clock, now, sources_.imu->live());
  imu.health = health_of(s.imu_lost.load(), imu, imu_stale);
  st.streams.push_back(std::move(imu));

  if (sources_.lidar) {
    StreamStatus lidar;
    lidar.name = "lidar";
    lidar.received = s.lidar_received.load();
    lidar.decoded = s.lidar_decoded.load();
    lidar.malformed = s.lidar_malformed.load();
    lidar.dropped = s.lidar_scans_dropped.load();
    ClockSyncStatus lclock;
    {
      std::lock_guard lock(s.snapshot_mutex);
      lclock = s.lidar_clock_status;
    }
    const bool lidar_stale = fill_clock(lidar, lclock, now, sources_.lidar->live());
    lidar.health = health_of(s.lidar_lost.load(), lidar, lidar_stale);
    st.streams.push_back(std::move(lidar));
    st.lidar_scans = s.lidar_scans.load();
    st.lidar_points = s.lidar_points.load();
    st.lidar_scans_fused = s.lidar_scans_fused.load();
  }
  return st;
}

}  // namespace posed::pipeline
