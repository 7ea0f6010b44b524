#include "daemon/pipeline/estimator_config.hpp"

#include <algorithm>
#include <cmath>

namespace posed::pipeline {

Eigen::Isometry3d to_isometry(const config::Transform4& T) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 3; ++col)
      out.linear()(r, col) = T[static_cast<std::size_t>(4 * r + col)];
    out.translation()[r] = T[static_cast<std::size_t>(4 * r + 3)];
  }
  return out;
}

estimator::LioConfig lio_config(const config::PosedConfig& c) {
  constexpr double kDeg = M_PI / 180.0;
  estimator::LioConfig l;
  l.gravity_mps2 = c.imu.gravity_mps2;
  l.noise = {.gyro_noise_density = c.imu.gyro_noise_density,
             .accel_noise_density = c.imu.accel_noise_density,
             .gyro_random_walk = c.imu.gyro_random_walk,
             .accel_random_walk = c.imu.accel_random_walk};
  l.backup_noise = imu::ImuNoise{.gyro_noise_density = c.realsense_imu.gyro_noise_density,
                                 .accel_noise_density = c.realsense_imu.accel_noise_density,
                                 .gyro_random_walk = c.realsense_imu.gyro_random_walk,
                                 .accel_random_walk = c.realsense_imu.accel_random_walk,
                                 .gyro_bias_offset_radps = c.realsense_imu.gyro_bias_offset_radps,
                                 .accel_bias_offset_mps2 = c.realsense_imu.accel_bias_offset_mps2};
  l.alignment = {.gravity_mps2 = c.imu.gravity_mps2,
                 .window = Duration::from_seconds(c.estimator.init_static_s),
                 .max_gyro_radps = c.estimator.init_max_gyro_radps,
                 .gyro_noise_density = c.imu.gyro_noise_density,
                 .accel_noise_density = c.imu.accel_noise_density};
  l.T_imu_lidar = to_isometry(c.extrinsics.T_imu_lidar);
  const auto& e = c.estimator;
  l.lidar.min_range_m = static_cast<float>(std::max(c.lidar.min_range_m, 1.0));
  l.lidar.max_range_m = static_cast<float>(c.lidar.max_range_m);
  l.lidar.features.columns = static_cast<int>(std::lround(60.0 / c.lidar.rpm / 55.296e-6));
  l.lidar.features.plane_voxel_m = e.plane_voxel_m;
  l.lidar.features.edge_voxel_m = e.edge_voxel_m;
  l.lidar.matcher.handle_degeneracy = e.degeneracy_handling;
  l.lidar.matcher.degeneracy_translation_threshold = e.degeneracy_translation_threshold;
  l.lidar.matcher.degeneracy_rotation_threshold_m2 = e.degeneracy_rotation_threshold_m2;
  l.lidar.matcher.degenerate_information_scale = e.degenerate_information_scale;
  l.lidar.map_radius_m = e.map_radius_m;
  l.lidar.edge_map.confirm_after_s = e.map_confirm_s;
  l.lidar.plane_map.confirm_after_s = e.map_confirm_s;
  l.lidar.keyframe_distance_m = e.keyframe_distance_m;
  l.lidar.keyframe_angle_rad = e.keyframe_angle_deg * kDeg;
  l.window.size = e.window_size;
  l.window.max_iterations = e.solver_iterations;
  l.window.estimate_gravity_tilt = e.estimate_gravity_tilt;
  l.window.gravity_tilt_prior_rad = e.gravity_tilt_prior_deg * kDeg;
  l.window.gravity_tilt_release_yaw_rad = e.gravity_tilt_release_heading_deg * kDeg;
  l.vehicle_motion = e.vehicle_motion == "always" ? estimator::LioConfig::VehicleMotion::kEveryState
                     : e.vehicle_motion == "blind"
                         ? estimator::LioConfig::VehicleMotion::kWhereBlind
                         : estimator::LioConfig::VehicleMotion::kOff;
  l.vehicle_min_yaw_rate_radps = e.vehicle_min_yaw_rate_dps * M_PI / 180.0;
  l.vehicle_lateral_sigma_mps = e.vehicle_lateral_sigma_mps;
  l.vehicle_vertical_sigma_mps = e.vehicle_vertical_sigma_mps;
  l.vehicle_centre_m = {e.vehicle_centre_x_m, e.vehicle_centre_y_m, e.vehicle_centre_z_m};
  l.max_speed_mps = e.max_speed_mps;
  l.max_gyro_bias_radps = e.max_gyro_bias_radps;
  l.max_accel_bias_mps2 = e.max_accel_bias_mps2;
  l.max_match_jump_m = e.max_match_jump_m;
  l.max_match_jump_rad = e.max_match_jump_deg * kDeg;
  l.pose_selection = e.pose_selection;
  l.aided_degeneracy_translation_threshold = e.camera_degeneracy_translation_threshold;
  l.aided_degenerate_information_scale = e.camera_degenerate_information_scale;
  // The matcher's information is point constraints over its residual variance.
  l.aided_trusted_information =
      e.camera_lidar_trusted_constraints /
      (l.lidar.matcher.residual_sigma_m * l.lidar.matcher.residual_sigma_m);
  l.aided_consistency_sigma = e.camera_lidar_consistency_sigma;
  l.aided_suspect_window_s = e.camera_lidar_suspect_window_s;
  l.aided_blind_weak_ratio = e.camera_blind_weak_lidar_ratio;
  l.aided_settled_after_s = e.camera_strong_lidar_after_s;
  return l;
}

StrapdownConfig strapdown_config(const config::PosedConfig& c) {
  return StrapdownConfig{
      .gravity_mps2 = c.imu.gravity_mps2,
      .init_static = Duration::from_seconds(c.estimator.init_static_s),
      .init_max_gyro_radps = c.estimator.init_max_gyro_radps,
      .gyro_noise_density = c.imu.gyro_noise_density,
      .accel_noise_density = c.imu.accel_noise_density,
  };
}

mapping::LoopClosureConfig loop_closure_config(const config::PosedConfig& config) {
  const config::MappingSection& m = config.mapping;
  mapping::LoopClosureConfig c;
  c.keyframe_distance_m = config.estimator.keyframe_distance_m;
  c.keyframe_angle_rad = config.estimator.keyframe_angle_deg * M_PI / 180.0;
  c.keyframe_voxel_m = m.keyframe_voxel_m;
  c.keyframe_max_range_m = m.keyframe_max_range_m;
  c.scan_context.max_range_m = m.scan_context_max_range_m;
  c.mapped_keyframe_distance_m = m.mapped_keyframe_distance_m;
  c.attempt_every_keyframes = m.attempt_every_keyframes;
  c.min_separation_s = m.min_separation_s;
  c.search_radius_m = m.search_radius_m;
  c.scan_context_max_distance = m.scan_context_max_distance;
  c.registration.max_rms_m = m.max_rms_m;
  c.registration.min_overlap = m.min_overlap;
  c.registration.min_constraint = m.min_constraint;
  c.odometry_sigma_translation_degenerate_per_m = m.degenerate_sigma_per_m;
  c.odometry_sigma_rotation_degenerate_per_m = m.degenerate_rotation_sigma_per_m;
  c.loop_max_correction_sigmas = m.loop_max_correction_sigmas;
  return c;
}

mapping::LocalisationConfig localisation_config(const config::PosedConfig& config) {
  const config::MappingSection& m = config.mapping;
  mapping::LocalisationConfig c;
  c.keyframe_distance_m = m.localise_every_m;
  c.keyframe_angle_rad = config.estimator.keyframe_angle_deg * M_PI / 180.0;
  c.lost_after_m = m.lost_after_m;
  c.max_range_m = m.localise_max_range_m;
  c.first_fix_min_constraint = m.first_fix_min_constraint;
  c.scan_context_max_distance = m.localise_scan_context_max_distance;
  c.registration.max_rms_m = m.max_rms_m;
  c.registration.min_overlap = m.min_overlap;
  c.registration.min_constraint = m.min_constraint;
  return c;
}

Eigen::Isometry3d initial_pose(const config::MappingSection& m) {
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  T_map_base.translation() = Eigen::Vector3d(m.initial_x_m, m.initial_y_m, m.initial_z_m);
  T_map_base.linear() =
      Eigen::AngleAxisd(m.initial_yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  return T_map_base;
}

}  // namespace posed::pipeline
