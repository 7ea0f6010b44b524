#include "tools/sim/simulator.hpp"

#include <cmath>
#include <optional>
#include <queue>
#include <random>

#include "drivers/camera/d4xx_metadata_writer.hpp"
#include "drivers/common/wire_format.hpp"
#include "drivers/recording/raw_channels.hpp"
#include "drivers/velodyne/packet_format.hpp"
#include "drivers/velodyne/position_packet.hpp"
#include "tools/sim/bvh.hpp"
#include "tools/sim/lidar_model.hpp"
#include "tools/sim/moving_objects.hpp"
#include "tools/sim/scenarios.hpp"
#include "tools/sim/visible_camera.hpp"

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

/// Everything generated but not yet written, released in host-arrival order.
class ArrivalQueue {
 public:
  void push(std::int64_t host_ns, int stream, std::vector<std::byte> bytes) {
    Pending p;
    p.host_ns = host_ns;
    p.seq = seq_++;
    p.stream = stream;
    p.bytes = std::move(bytes);
    queue_.push(std::move(p));
  }
  void push_pose(std::int64_t host_ns, const GroundTruthPose& pose) {
    Pending p;
    p.host_ns = host_ns;
    p.seq = seq_++;
    p.pose = pose;
    queue_.push(std::move(p));
  }
  /// Writes everything that arrives before `host_ns`; false when the sink fails.
  bool flush_until(std::int64_t host_ns, SimSink& sink) {
    while (!queue_.empty() && queue_.top().host_ns < host_ns) {
      const Pending& p = queue_.top();
      const bool ok = p.stream < 0
                          ? sink.write_ground_truth(HostTime::from_ns(p.host_ns), p.pose)
                          : sink.write_raw(p.stream, HostTime::from_ns(p.host_ns), p.bytes);
      if (!ok) return false;
      queue_.pop();
    }
    return true;
  }

 private:
  std::priority_queue<Pending, std::vector<Pending>, std::greater<>> queue_;
  std::uint64_t seq_ = 0;
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

/// A camera frame and, for the D435i's nodes, the metadata buffer the V4L2 Source delivers
/// just before it (it completes with the frame and is read first).
template <class D4xxCamera>
std::vector<std::byte> d4xx_frame(D4xxCamera& camera, HostTime arrival, int metadata_stream,
                                  ArrivalQueue& queue) {
  std::vector<std::byte> metadata;
  encode_d4xx_metadata(camera.next_metadata(arrival), metadata);
  queue.push(arrival.ns, metadata_stream, std::move(metadata));
  std::vector<std::byte> frame;
  camera.emit(frame);
  return frame;
}

}  // namespace

bool run_simulation(const SimRig& rig, const SimOptions& options, SimSink& sink,
                    SimSummary& summary, std::string& error, const SimProgress& progress) {
  if (!(options.duration_s > 0) || options.duration_s > 24 * 3600.0) {
    error = "duration must be in (0, 86400] s";
    return false;
  }
  std::optional<Scenario> scenario =
      make_scenario(options.scenario, options.seed, options.drive_seed, options.duration_s,
                    rig.gravity_mps2, error);
  if (!scenario) return false;
  const Trajectory& trajectory = scenario->trajectory;
  const Bvh bvh(scenario->world);
  // People and vehicles (--dynamic): appended to the world after its BVH, placed by each sensor
  // at its sample time. Their own RNG, so the static world and every other draw stay the seed's.
  std::optional<MovingObjects> moving;
  if (options.dynamic) {
    moving.emplace(scenario->world, trajectory, options.scenario == "street_night",
                   options.seed ^ 0xD7A41C0B7EC75ull);
  }
  const SensorScene scene{scenario->world, bvh, trajectory, moving ? &*moving : nullptr};
  summary = {};
  summary.boxes = scenario->world.boxes.size();
  if (moving) summary.moving_objects = moving->describe();
  summary.path_length_m = trajectory.path().length();
  summary.host_to_wall_ns = kSimWallStartNs - options.host_epoch_ns;

  // Independent RNG streams per device, all derived from the seed. The depth camera draws last,
  // so turning it on leaves every other stream's bytes as they were.
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
  LidarModel lidar(lidar_cfg, calibration, scene, lidar_clock, next_seed());

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
  VisibleCamera visible(vis_cfg, scene, vis_clock, next_seed());

  ThermalCameraConfig th_cfg;
  th_cfg.intrinsics = rig.thermal;
  th_cfg.T_base_cam = rig.T_imu_cam * rig.T_cam_thermal;
  th_cfg.rate_hz = rig.thermal_rate_hz;
  th_cfg.format = rig.thermal_format;
  th_cfg.noise = options.noise;
  ClockModel th_clock(clocks.thermal, epoch, next_seed());
  ThermalCamera thermal(th_cfg, scene, th_clock, next_seed());

  // The depth node runs on the D435i's clock (the colour node's) with its own transport jitter
  // and a frame phase of its own: the two nodes stream independently.
  DepthCameraConfig depth_cfg = rig.depth;
  depth_cfg.T_base_depth = rig.T_imu_cam * rig.T_cam_depth;
  depth_cfg.noise = options.noise;
  ClockModel depth_clock(clocks.visible, epoch, next_seed());
  const auto depth_phase = Duration::from_seconds(
      std::uniform_real_distribution<double>(0, 1.0 / depth_cfg.rate_hz)(seeder));
  DepthCamera depth(depth_cfg, scene, depth_clock, next_seed(), depth_phase);

  // The D435i's IMU: its clock is the camera's, its transport USB HID (a report every sample,
  // 1-2 ms). It draws after everything else, so turning it on leaves every other stream's bytes
  // as they were.
  RealsenseImuModelConfig rsimu_cfg = rig.realsense_imu;
  rsimu_cfg.T_base_rsimu = rig.T_imu_cam * rig.T_cam_depth * rig.T_depth_rsimu;
  rsimu_cfg.noise = options.noise;
  ClockModelConfig rsimu_clock_cfg = clocks.visible;
  rsimu_clock_cfg.latency_ns = 1'000'000;
  rsimu_clock_cfg.jitter_mean_ns = options.noise ? 500'000 : 0;
  std::optional<ClockModel> accel_clock, gyro_clock;
  std::optional<RealsenseImuModel> rsimu;
  if (options.realsense_imu) {
    accel_clock.emplace(rsimu_clock_cfg, epoch, next_seed());
    gyro_clock.emplace(rsimu_clock_cfg, epoch, next_seed());
    rsimu.emplace(rsimu_cfg, trajectory, *gyro_clock, next_seed());
  }

  // Streams, named as the daemon's Sources name them (raw_channels.hpp).
  std::string scen = "sim " + options.scenario + " seed " + std::to_string(options.seed);
  if (options.drive_seed) {
    scen += " drive seed " + std::to_string(*options.drive_seed);
  }
  int s_imu = -1, s_lidar = -1, s_pos = -1, s_vis = -1, s_vis_meta = -1, s_th = -1;
  int s_depth = -1, s_depth_meta = -1, s_rs_accel = -1, s_rs_gyro = -1;
  bool refused = false;
  auto add = [&](const char* name, std::string_view wire, std::uint32_t channel,
                 const std::map<std::string, std::string>& md) {
    const int id = sink.add_stream({name, std::string(wire), channel, md});
    refused = refused || id < 0;
    return id;
  };
  auto camera_md = [&](const CameraIntrinsics& K, double rate, const ClockModelConfig& c,
                       bool clock) {
    auto md = clock_metadata(c, clock);
    md["width"] = std::to_string(K.width);
    md["height"] = std::to_string(K.height);
    md["rate_hz"] = num(rate);
    md["device"] = scen;
    return md;
  };
  if (options.imu) {
    auto md = clock_metadata(clocks.imu, true);
    md["rate_hz"] = num(rig.imu.rate_hz);
    md["device"] = scen;
    s_imu = add("imu", raw::kWireA9Serial, 0, md);
  }
  if (options.lidar) {
    auto md = clock_metadata(clocks.lidar, true);
    md["rpm"] = num(rig.lidar_rpm);
    md["calibration"] = calibration.source;
    md["device"] = scen;
    s_lidar = add("lidar", raw::kWireVelodyneData, 0, md);
    s_pos = add("lidar", raw::kWireVelodynePosition, 1, md);
  }
  if (options.visible_camera) {
    const auto md = camera_md(rig.visible, rig.visible_rate_hz, clocks.visible, true);
    s_vis = add("visible", "yuyv", 0, md);
    // The D435i's frame metadata, on the Source channel the V4L2 Source gives it.
    s_vis_meta = add("visible", drivers::wire::kUvcMetaD4xx, 1, md);
  }
  if (options.thermal_camera) {
    s_th = add("thermal", to_string(rig.thermal_format), 0,
               camera_md(rig.thermal, rig.thermal_rate_hz, clocks.thermal, false));
  }
  if (options.depth_camera) {
    auto md = camera_md(depth_cfg.intrinsics, depth_cfg.rate_hz, clocks.visible, true);
    md["depth_unit_m"] = num(depth_cfg.depth_unit_m);
    md["baseline_m"] = num(depth_cfg.baseline_m);
    s_depth = add("depth", "z16", 0, md);
    s_depth_meta = add("depth", drivers::wire::kUvcMetaD4xx, 1, md);
  }
  if (options.realsense_imu) {
    auto md = clock_metadata(rsimu_clock_cfg, true);
    md["accel_rate_hz"] = num(rsimu_cfg.accel_rate_hz);
    md["gyro_rate_hz"] = num(rsimu_cfg.gyro_rate_hz);
    md["device"] = scen;
    // Channel 0 accel, 1 gyro, as RealsenseImuSource delivers them.
    s_rs_accel = add("realsense_imu", realsense_accel_wire_format(), 0, md);
    s_rs_gyro = add("realsense_imu", realsense_gyro_wire_format(), 1, md);
  }
  if (refused) {
    error = "the sink refused a stream";
    return false;
  }

  ArrivalQueue queue;
  // Sends everything a device completes before `w1`, stamped with its host arrival.
  auto drain = [&](Duration w1, ClockModel& clock, int stream, std::uint64_t& count,
                   auto&& next_send, auto&& bytes_arriving_at) {
    while (next_send() < w1) {
      const HostTime arrival = clock.arrival(next_send());
      queue.push(arrival.ns, stream, bytes_arriving_at(arrival));
      ++count;
    }
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
      queue.push_pose(epoch + next_gt.ns,
                      {s.p_map_base_m, s.q_map_base, s.v_map_mps, s.w_base_radps});
      summary.distance_m += (s.p_map_base_m - last_p).norm();
      last_p = s.p_map_base_m;
      ++summary.ground_truth_poses;
      next_gt = Duration::from_ns(std::llround(static_cast<double>(summary.ground_truth_poses) *
                                               static_cast<double>(gt_period.ns)));
    }
    if (options.imu) {
      drain(
          w1, imu_clock, s_imu, summary.imu_frames, [&] { return imu.next_send(); },
          [&](HostTime) {
            const std::size_t n = imu.emit(imu_buf);
            const auto* b = reinterpret_cast<const std::byte*>(imu_buf.data());
            return std::vector<std::byte>(b, b + n);
          });
    }
    if (options.lidar) {
      drain(
          w1, lidar_clock, s_lidar, summary.lidar_packets, [&] { return lidar.next_data_send(); },
          [&](HostTime) {
            std::vector<std::byte> bytes(drivers::velodyne::kDataPacketBytes);
            lidar.emit_data(bytes);
            return bytes;
          });
      drain(
          w1, position_clock, s_pos, summary.position_packets,
          [&] { return lidar.next_position_send(); },
          [&](HostTime) {
            std::vector<std::byte> bytes(drivers::velodyne::kPositionPacketBytes);
            lidar.emit_position(bytes);
            return bytes;
          });
    }
    if (options.visible_camera) {
      drain(
          w1, vis_clock, s_vis, summary.visible_frames, [&] { return visible.next_send(); },
          [&](HostTime arrival) { return d4xx_frame(visible, arrival, s_vis_meta, queue); });
    }
    if (options.thermal_camera) {
      drain(
          w1, th_clock, s_th, summary.thermal_frames, [&] { return thermal.next_send(); },
          [&](HostTime) {
            std::vector<std::byte> bytes;
            thermal.emit(bytes);
            return bytes;
          });
    }
    if (options.depth_camera) {
      drain(
          w1, depth_clock, s_depth, summary.depth_frames, [&] { return depth.next_send(); },
          [&](HostTime arrival) { return d4xx_frame(depth, arrival, s_depth_meta, queue); });
    }
    if (rsimu) {
      drain(
          w1, *accel_clock, s_rs_accel, summary.realsense_accel_records,
          [&] { return rsimu->next_accel(); }, [&](HostTime) { return rsimu->emit_accel(); });
      drain(
          w1, *gyro_clock, s_rs_gyro, summary.realsense_gyro_records,
          [&] { return rsimu->next_gyro(); }, [&](HostTime) { return rsimu->emit_gyro(); });
    }
    if (!queue.flush_until(epoch + w1.ns, sink)) {
      error = "the sink failed to write";
      return false;
    }
    if (progress && w1.seconds() - last_progress >= 1.0) {
      last_progress = w1.seconds();
      if (!progress(w1.seconds())) break;
    }
  }
  if (!queue.flush_until(INT64_MAX, sink)) {
    error = "the sink failed to write";
    return false;
  }
  summary.lidar_rays = lidar.rays();
  summary.lidar_returns = lidar.returns();
  return true;
}

}  // namespace posed::sim
