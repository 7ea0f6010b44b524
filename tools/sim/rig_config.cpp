#include "tools/sim/rig_config.hpp"

#include "daemon/pipeline/estimator_config.hpp"

namespace posed::sim {
namespace {

CameraIntrinsics to_intrinsics(const config::CameraSection& c) {
  return {c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2};
}

}  // namespace

SimRig rig_from_config(const config::PosedConfig& cfg) {
  SimRig rig;
  rig.T_imu_lidar = pipeline::to_isometry(cfg.extrinsics.T_imu_lidar);
  rig.T_imu_cam = pipeline::to_isometry(cfg.extrinsics.T_imu_cam);
  rig.T_cam_thermal = pipeline::to_isometry(cfg.extrinsics.T_cam_thermal);
  rig.T_cam_depth = pipeline::to_isometry(cfg.extrinsics.T_cam_depth);
  rig.T_depth_rsimu = pipeline::to_isometry(cfg.extrinsics.T_depth_rsimu);
  rig.realsense_imu.accel_rate_hz = cfg.realsense_imu.accel_rate_hz;
  rig.realsense_imu.gyro_rate_hz = cfg.realsense_imu.gyro_rate_hz;
  rig.imu.rate_hz = cfg.imu.rate_hz;
  rig.imu.gyro_noise_density = cfg.imu.gyro_noise_density;
  rig.imu.gyro_random_walk = cfg.imu.gyro_random_walk;
  rig.imu.accel_noise_density = cfg.imu.accel_noise_density;
  rig.imu.accel_random_walk = cfg.imu.accel_random_walk;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c)
      rig.imu.mounting.R_imu_sensor[r][c] = cfg.imu.R_imu_sensor[3 * r + c];
  rig.gravity_mps2 = cfg.imu.gravity_mps2;
  rig.lidar_rpm = cfg.lidar.rpm;
  rig.visible = to_intrinsics(cfg.visible_camera);
  rig.visible_rate_hz = cfg.visible_camera.rate_hz;
  rig.thermal = to_intrinsics(cfg.thermal_camera);
  rig.thermal_rate_hz = cfg.thermal_camera.rate_hz;
  // Formats other than the two the simulator writes (yuyv, mjpeg) leave the default y8; the
  // caller says so (posectl sim refuses them).
  rig.thermal_format =
      thermal_format_from_string(cfg.thermal_camera.format).value_or(ThermalFormat::kY8);
  rig.thermal_latency_s = cfg.thermal_camera.latency_s;
  rig.visible_latency_s = cfg.visible_camera.latency_s;
  const config::DepthCameraSection& d = cfg.depth_camera;
  rig.depth.intrinsics = {d.width, d.height, d.fx, d.fy, d.cx, d.cy, 0, 0, 0, 0};
  rig.depth.rate_hz = d.rate_hz;
  rig.depth.baseline_m = d.baseline_m;
  rig.depth.depth_unit_m = d.depth_unit_m;
  rig.depth.min_range_m = d.min_range_m;
  rig.depth.max_range_m = d.max_range_m;
  return rig;
}

}  // namespace posed::sim
