#include "tools/sim/simulator.hpp"

#include <cmath>
#include <memory>
#include <optional>
#include <queue>
#include <random>

#include "drivers/common/wire_format.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "drivers/velodyne/packet_format.hpp"
#include "drivers/velodyne/position_packet.hpp"
#include "tools/sim/bvh.hpp"
#include "tools/sim/d4xx_metadata_encoder.hpp"
#include "tools/sim/lidar_model.hpp"
#include "tools/sim/scenarios.hpp"

namespace posed::sim {
namespace {

namespace raw = drivers::recording::raw;

/// One output waiting for its host arrival time.
struct Pending {
  std::int64_t host_ns = 0;
  std::uint64_t seq = 0;  // generation order: ties resolve deterministically
  int stream = -1;        // -1 = ground truth
  std::vector<std::byte> bytes;
  GroundTruthPose pose;
  bool operator>(const Pending& o) const {
    return host_ns != o.host_ns ? host_ns > o.host_ns : seq > o.seq;
  }
};

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::map<std::string, std::string> clock_metadata(const ClockModelConfig& c, bool has_clock) {
  return {{"sim.clock", has_clock ? "device" : "none"},
          {"sim.clock_offset_ns", std::to_string(c.offset_ns)},
          {"sim.clock_drift_ppm", num(c.drift_ppm)},
          {"sim.latency_ns", std::to_string(c.latency_ns)},
          {"sim.jitter_mean_ns", std::to_string(c.jitter_mean_ns)}};
}

/// What the D435i reports about the next visible frame. Its auto-exposure is modelled as one
/// amplification (VisibleCamera::gain); reported as the real one splits it: exposure first, up
/// to half the frame interval, then analog gain (64 = 1x).
D4xxFrameFacts visible_metadata(const VisibleCamera& camera, const SimRig& rig, HostTime arrival) {
  D4xxFrameFacts f;
  const double interval_us = 1e6 / rig.visible_rate_hz;
  const double max_exposure_us = interval_us / 2;
  const double exposure_us = max_exposure_us * std::min(camera.gain(), 1.0);
  const std::int64_t mid_us = camera.next_exposure_mid().ns / 1000;
  f.frame_counter = static_cast<std::uint32_t>(camera.frames());
  f.sensor_timestamp_us = static_cast<std::uint32_t>(mid_us);  // the device counter wraps
  f.pts_us = static_cast<std::uint32_t>(mid_us - std::llround(exposure_us / 2));
  f.exposure_time_us = static_cast<std::uint32_t>(std::llround(exposure_us));
  f.frame_interval_us = static_cast<std::uint32_t>(std::llround(interval_us));
  f.gain = static_cast<std::uint32_t>(std::llround(64 * std::max(camera.gain(), 1.0)));
  f.width_px = static_cast<std::uint16_t>(rig.visible.width);
  f.height_px = static_cast<std::uint16_t>(rig.visible.height);
  f.fps = static_cast<std::uint16_t>(std::lround(rig.visible_rate_hz));
  // uvc_meta_buf.ns: the frame's first USB packet, about half a frame interval before the last.
  f.host_sof_ns = static_cast<std::uint64_t>(arrival.ns - std::llround(interval_us * 500));
  f.usb_sof = static_cast<std::uint16_t>((f.host_sof_ns / 1'000'000) & 0x7FF);
  return f;
}

/// Per-device clocks for a seed (offsets, drifts tens of ppm) and transports.
struct Clocks {
  ClockModelConfig lidar, imu, visible, thermal;
};
Clocks make_clocks(std::mt19937_64& rng, const SimRig& rig, bool noise) {
  auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  Clocks c;
  // Lidar: UTC-like clock of the day 2024-06-01, somewhere between 08:00 and 20:00.
  c.lidar = {static_cast<std::int64_t>(u(8 * 3600.0, 20 * 3600.0) * 1e9), u(-30, 30), 250'000,
             100'000};
  // A9: µs since power-on, anywhere in its 71.6 min wrap (some runs wrap).
  c.imu = {static_cast<std::int64_t>(u(1.0, 4294.0) * 1e9), u(-50, 50), 600'000, 300'000};
  // D435i: hardware clock since power-on; frame readout and USB transfer.
  // A frame is sent once read out, half a frame after its exposure midpoint (VisibleCamera);
  // the rest of the configured latency is the USB transfer.
  const double visible_transfer_s =
      std::max(rig.visible_latency_s - 0.5 / rig.visible_rate_hz, 1e-3);
  c.visible = {static_cast<std::int64_t>(u(1.0, 1e4) * 1e9), u(-30, 30),
               static_cast<std::int64_t>(visible_transfer_s * 1e9), 2'000'000};
  // Thermal: no clock; its frame oscillator still drifts; stamped on arrival.
  c.thermal = {0, u(-100, 100), static_cast<std::int64_t>(rig.thermal_latency_s * 1e9), 3'000'000};
  if (!noise) {
    for (ClockModelConfig* m : {&c.lidar, &c.imu, &c.visible, &c.thermal}) m->jitter_mean_ns = 0;
  }
  return c;
}

}  // namespace

bool run_simulation(const SimRig& rig, const SimOptions& options, SimSink& sink,
                    SimSummary& summary, std::string& error, const SimProgress& progress) {
  if (!(options.duration_s > 0) || options.duration_s > 24 * 3600.0) {
    error = "duration must be in (0, 86400] s";
    return false;
  }
  std::optional<Scenario> scenario =
      make_scenario(options.scenario, options.seed, options.duration_s, rig.gravity_mps2, error);
  if (!scenario) return false;
  const World& world = scenario->world;
  const Trajectory& trajectory = scenario->trajectory;
  const Bvh bvh(world);
  summary = {};
  summary.boxes = world.boxes.size();
  summary.path_length_m = trajectory.path().length();
  summary.host_to_wall_ns = kSimWallStartNs - options.host_epoch_ns;

  // Independent RNG streams per device, all derived from the seed.
  std::mt19937_64 seeder(options.seed ^ 0x5EEDC0FFEEull);
  const Clocks clocks = make_clocks(seeder, rig, options.noise);
  const std::int64_t epoch = options.host_epoch_ns;
  auto next_seed = [&] { return seeder(); };

  drivers::velodyne::Calibration calibration =
      rig.lidar_calibration.lasers.empty()
          ? drivers::velodyne::builtin_calibration(drivers::velodyne::ProductId::kVlp32c)
          : rig.lidar_calibration;
  LidarModelConfig lidar_cfg;
  lidar_cfg.T_base_lidar = rig.T_imu_lidar;
  lidar_cfg.rpm = rig.lidar_rpm;
  lidar_cfg.azimuth0_deg = std::uniform_real_distribution<double>(0, 360)(seeder);
  lidar_cfg.noise = options.noise;
  ClockModel lidar_clock(clocks.lidar, epoch, next_seed());
  ClockModel position_clock(clocks.lidar, epoch, next_seed());
  LidarModel lidar(lidar_cfg, calibration, world, bvh, trajectory, lidar_clock, next_seed());

  ImuModelConfig imu_cfg = rig.imu;
  imu_cfg.noise = options.noise;
  ClockModel imu_clock(clocks.imu, epoch, next_seed());
  ImuModel imu(imu_cfg, trajectory, imu_clock, next_seed());

  VisibleCameraConfig vis_cfg;
  vis_cfg.intrinsics = rig.visible;
  vis_cfg.T_base_cam = rig.T_imu_cam;
  vis_cfg.rate_hz = rig.visible_rate_hz;
  vis_cfg.noise = options.noise;
  ClockModel vis_clock(clocks.visible, epoch, next_seed());
  VisibleCamera visible(vis_cfg, world, bvh, trajectory, vis_clock, next_seed());

  ThermalCameraConfig th_cfg;
  th_cfg.intrinsics = rig.thermal;
  th_cfg.T_base_cam = rig.T_imu_cam * rig.T_cam_thermal;
  th_cfg.rate_hz = rig.thermal_rate_hz;
  th_cfg.noise = options.noise;
  ClockModel th_clock(clocks.thermal, epoch, next_seed());
  ThermalCamera thermal(th_cfg, world, bvh, trajectory, th_clock, next_seed());

  // Streams, named as the daemon's Sources name them (raw_channels.hpp).
  const std::string scen = "sim " + options.scenario + " seed " + std::to_string(options.seed);
  int s_imu = -1, s_lidar = -1, s_pos = -1, s_vis = -1, s_vis_meta = -1, s_th = -1;
  if (options.imu) {
    auto md = clock_metadata(clocks.imu, true);
    md["rate_hz"] = num(rig.imu.rate_hz);
    md["device"] = scen;
    s_imu = sink.add_stream({"imu", std::string(raw::kWireA9Serial), 0, md});
  }
  if (options.lidar) {
    auto md = clock_metadata(clocks.lidar, true);
    md["rpm"] = num(rig.lidar_rpm);
    md["calibration"] = calibration.source;
    md["device"] = scen;
    s_lidar = sink.add_stream({"lidar", std::string(raw::kWireVelodyneData), 0, md});
    s_pos = sink.add_stream({"lidar", std::string(raw::kWireVelodynePosition), 1, md});
  }
  auto camera_md = [&](const CameraIntrinsics& K, double rate, const ClockModelConfig& c,
                       bool clock) {
    auto md = clock_metadata(c, clock);
    md["width"] = std::to_string(K.width);
    md["height"] = std::to_string(K.height);
    md["rate_hz"] = num(rate);
    md["device"] = scen;
    return md;
  };
  if (options.visible_camera) {
    const auto md = camera_md(rig.visible, rig.visible_rate_hz, clocks.visible, true);
    s_vis = sink.add_stream({"visible", "yuyv", 0, md});
    // The D435i's frame metadata, on the Source channel the V4L2 Source gives it.
    s_vis_meta = sink.add_stream({"visible", std::string(drivers::wire::kUvcMetaD4xx), 1, md});
  }
  if (options.thermal_camera)
    s_th = sink.add_stream(
        {"thermal", "y8", 0, camera_md(rig.thermal, rig.thermal_rate_hz, clocks.thermal, false)});
  if ((options.imu && s_imu < 0) || (options.lidar && (s_lidar < 0 || s_pos < 0)) ||
      (options.visible_camera && (s_vis < 0 || s_vis_meta < 0)) ||
      (options.thermal_camera && s_th < 0)) {
    error = "the sink refused a stream";
    return false;
  }

  std::priority_queue<Pending, std::vector<Pending>, std::greater<>> pending;
  std::uint64_t seq = 0;
  auto push = [&](std::int64_t host_ns, int stream, std::vector<std::byte> bytes) {
    Pending p;
    p.host_ns = host_ns;
    p.seq = seq++;
    p.stream = stream;
    p.bytes = std::move(bytes);
    pending.push(std::move(p));
  };
  auto flush_until = [&](std::int64_t host_ns) {
    while (!pending.empty() && pending.top().host_ns < host_ns) {
      const Pending& p = pending.top();
      const bool ok = p.stream < 0
                          ? sink.write_ground_truth(HostTime::from_ns(p.host_ns), p.pose)
                          : sink.write_raw(p.stream, HostTime::from_ns(p.host_ns), p.bytes);
      if (!ok) return false;
      pending.pop();
    }
    return true;
  };

  const Duration end = Duration::from_seconds(options.duration_s);
  const Duration window = Duration::from_ms(20);
  const auto gt_period = Duration::from_seconds(1.0 / options.ground_truth_rate_hz);
  Duration next_gt = Duration::from_ns(0);
  std::vector<std::uint8_t> imu_buf(drivers::a9::kMaxFrameSize);
  Eigen::Vector3d last_p = trajectory.at(0.0).p_map_base_m;
  double last_progress = 0;

  for (Duration w0 = Duration::from_ns(0); w0 < end; w0 += window) {
    const Duration w1 = std::min(w0 + window, end);
    // Everything sent in [w0, w1): arrivals are ≥ the send time, so after this window nothing
    // can arrive before host(w1) any more and those messages can go out in order.
    while (next_gt < w1) {
      const TrajectorySample s = trajectory.at(next_gt);
      Pending p;
      p.host_ns = epoch + next_gt.ns;
      p.seq = seq++;
      p.pose = {s.p_map_base_m, s.q_map_base, s.v_map_mps, s.w_base_radps};
      summary.distance_m += (s.p_map_base_m - last_p).norm();
      last_p = s.p_map_base_m;
      pending.push(std::move(p));
      ++summary.ground_truth_poses;
      next_gt = Duration::from_ns(std::llround(static_cast<double>(summary.ground_truth_poses) *
                                               static_cast<double>(gt_period.ns)));
    }
    if (options.imu) {
      while (imu.next_send() < w1) {
        const Duration sent = imu.next_send();
        const std::size_t n = imu.emit(imu_buf);
        const auto* b = reinterpret_cast<const std::byte*>(imu_buf.data());
        push(imu_clock.arrival(sent).ns, s_imu, std::vector<std::byte>(b, b + n));
        ++summary.imu_frames;
      }
    }
    if (options.lidar) {
      while (lidar.next_data_send() < w1) {
        const Duration sent = lidar.next_data_send();
        std::vector<std::byte> bytes(drivers::velodyne::kDataPacketBytes);
        lidar.emit_data(bytes);
        push(lidar_clock.arrival(sent).ns, s_lidar, std::move(bytes));
        ++summary.lidar_packets;
      }
      while (lidar.next_position_send() < w1) {
        const Duration sent = lidar.next_position_send();
        std::vector<std::byte> bytes(drivers::velodyne::kPositionPacketBytes);
        lidar.emit_position(bytes);
        push(position_clock.arrival(sent).ns, s_pos, std::move(bytes));
        ++summary.position_packets;
      }
    }
    if (options.visible_camera) {
      while (visible.next_send() < w1) {
        const Duration sent = visible.next_send();
        // The metadata buffer completes with the frame and is read just before it.
        const HostTime arrival = vis_clock.arrival(sent);
        std::vector<std::byte> metadata;
        encode_d4xx_metadata(visible_metadata(visible, rig, arrival), metadata);
        push(arrival.ns, s_vis_meta, std::move(metadata));
        std::vector<std::byte> bytes;
        visible.emit(bytes);
        push(arrival.ns, s_vis, std::move(bytes));
        ++summary.visible_frames;
      }
    }
    if (options.thermal_camera) {
      while (thermal.next_send() < w1) {
        const Duration sent = thermal.next_send();
        std::vector<std::byte> bytes;
        thermal.emit(bytes);
        push(th_clock.arrival(sent).ns, s_th, std::move(bytes));
        ++summary.thermal_frames;
      }
    }
    if (!flush_until(epoch + w1.ns)) {
      error = "the sink failed to write";
      return false;
    }
    if (progress && w1.seconds() - last_progress >= 1.0) {
      last_progress = w1.seconds();
      if (!progress(w1.seconds())) break;
    }
  }
  if (!flush_until(INT64_MAX)) {
    error = "the sink failed to write";
    return false;
  }
  summary.lidar_rays = lidar.rays();
  summary.lidar_returns = lidar.returns();
  return true;
}

}  // namespace posed::sim
