#include "tools/sim/lidar_imu_run.hpp"

#include <algorithm>

#include "core/sync/clock_sync.hpp"
#include "drivers/common/wire_format.hpp"
#include "drivers/imu/a9_protocol.hpp"
#include "drivers/velodyne/scan_builder.hpp"

namespace posed::sim {

Eigen::Isometry3d LidarImuRun::T_map_base(HostTime t) const {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  if (truth.empty()) return out;
  const auto it =
      std::lower_bound(truth.begin(), truth.end(), t,
                       [](const MemorySink::Pose& p, HostTime s) { return p.stamp < s; });
  const MemorySink::Pose* a = nullptr;
  const MemorySink::Pose* b = nullptr;
  if (it == truth.begin()) {
    a = b = &truth.front();
  } else if (it == truth.end()) {
    a = b = &truth.back();
  } else {
    a = &*(it - 1);
    b = &*it;
  }
  const double span = static_cast<double>((b->stamp - a->stamp).ns);
  const double s =
      span > 0 ? std::clamp(static_cast<double>((t - a->stamp).ns) / span, 0.0, 1.0) : 0.0;
  out.linear() = a->pose.q_map_base.slerp(s, b->pose.q_map_base).toRotationMatrix();
  out.translation() = a->pose.p_map_base_m + s * (b->pose.p_map_base_m - a->pose.p_map_base_m);
  return out;
}

bool simulate_lidar_imu(const SimRig& rig, SimOptions options, LidarImuRun& out,
                        std::string& error) {
  options.visible_camera = options.thermal_camera = false;
  MemorySink sink;
  SimSummary summary;
  if (!run_simulation(rig, options, sink, summary, error)) return false;
  out = {};
  out.rig = rig;
  out.truth = std::move(sink.poses);

  const double rpm = rig.lidar_rpm;
  PayloadPool pool(4, drivers::velodyne::max_points_per_scan(rpm) * sizeof(LidarPoint));
  drivers::velodyne::ScanBuilder builder({}, {}, pool);
  ClockSync imu_clock(ClockSyncConfig{.kind = DeviceClockKind::kCounterUs32Bit,
                                      .nominal_rate_hz = rig.imu.rate_hz});
  drivers::a9::A9Decoder a9;
  const int lidar = sink.find("lidar", 0);
  const int imu = sink.find("imu", 0);
  drivers::velodyne::AssembledScan assembled;
  const auto take_scans = [&] {
    while (builder.pop(assembled)) {
      DecodedScan scan;
      scan.start = assembled.scan.start_stamp;
      scan.end = assembled.scan.end_stamp;
      const auto pts = assembled.scan.points.as<LidarPoint>();
      scan.points.assign(pts.begin(), pts.begin() + assembled.scan.point_count);
      out.scans.push_back(std::move(scan));
      assembled = {};  // the buffer back to the pool
    }
  };
  for (const MemorySink::Message& m : sink.messages) {
    if (m.stream == lidar) {
      builder.add_data(m.bytes, m.host_time);
      take_scans();
    } else if (m.stream == imu) {
      a9.feed(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(m.bytes.data()),
                                            m.bytes.size()),
              [&](const drivers::a9::A9Frame& f) {
                if (f.kind != drivers::a9::FrameKind::kSensor) return;
                const HostTime stamp = imu_clock.map_raw(f.sensor.counter_us, m.host_time);
                out.imu.push_back(drivers::a9::to_imu_sample(f.sensor, rig.imu.mounting, stamp,
                                                             imu_clock.status().last_device_stamp));
              });
    }
  }
  builder.flush();
  take_scans();
  return true;
}

}  // namespace posed::sim
