#include "daemon/pipeline/frontend_config.hpp"

#include <algorithm>
#include <cmath>

#include "daemon/pipeline/estimator_config.hpp"

namespace posed::pipeline {

bool frontend_mode(const std::string& name, vision::FrontendMode& mode) {
  if (name == "visible" || name == kTwoStreams) {
    mode = vision::FrontendMode::kVisible;
  } else if (name == "thermal") {
    mode = vision::FrontendMode::kThermal;
  } else if (name == "fused") {
    mode = vision::FrontendMode::kFused;
  } else {
    return false;
  }
  return true;
}

vision::PinholeCamera pinhole(const config::CameraSection& c) {
  vision::PinholeCamera p;
  p.width = c.width;
  p.height = c.height;
  p.fx = c.fx;
  p.fy = c.fy;
  p.cx = c.cx;
  p.cy = c.cy;
  p.k1 = c.k1;
  p.k2 = c.k2;
  p.p1 = c.p1;
  p.p2 = c.p2;
  return p;
}

fusion::CameraFrontEndConfig camera_front_end_config(const config::PosedConfig& config,
                                                     bool has_visible, bool has_thermal,
                                                     bool in_stamp_order, std::string& note) {
  const config::FrontendSection& s = config.frontend;
  fusion::CameraFrontEndConfig c;
  vision::FrontendConfig& f = c.frontend;
  if (!frontend_mode(s.mode, f.mode)) f.mode = vision::FrontendMode::kFused;
  note.clear();
  const bool two_streams = s.mode == kTwoStreams && has_visible && has_thermal;
  if (two_streams) {
    // Visible is the primary run (the status's front-end figures); thermal runs beside it on
    // the same events with its own tracks, quality and factors.
    c.compare_modes.push_back(vision::FrontendMode::kThermal);
  } else if (!has_visible && f.mode != vision::FrontendMode::kThermal) {
    note = "no visible camera: the front end runs in thermal mode instead of " + s.mode;
    f.mode = vision::FrontendMode::kThermal;
  } else if (!has_thermal && f.mode != vision::FrontendMode::kVisible) {
    note = "no thermal camera: the front end runs in visible mode instead of " + s.mode;
    f.mode = vision::FrontendMode::kVisible;
  }
  f.visible_camera = pinhole(config.visible_camera);
  f.thermal_camera = pinhole(config.thermal_camera);
  f.T_cam_thermal = to_isometry(config.extrinsics.T_cam_thermal);
  f.visible_enhance.enabled = s.enhance_visible;
  f.visible_enhance.target_mean = s.gamma_target_mean;
  f.visible_enhance.clahe_clip_limit = s.clahe_clip_limit;
  if (s.thermal_registration == "plane") {
    f.thermal_align.mode = vision::AlignMode::kPlane;
  } else if (s.thermal_registration == "fov_crop") {
    f.thermal_align.mode = vision::AlignMode::kFovCrop;
  } else if (s.thermal_registration == "lidar_depth") {
    f.thermal_align.mode = vision::AlignMode::kLidarDepth;
  } else {
    f.thermal_align.mode = vision::AlignMode::kInfiniteHomography;
  }
  f.thermal_align.plane_depth_m = s.thermal_plane_depth_m;
  f.thermal_align.depth_grid_cols = s.thermal_depth_grid_cols;
  f.thermal_align.depth_grid_rows = s.thermal_depth_grid_rows;
  f.thermal_align.rotation_compensation = s.rotation_compensation;
  f.thermal_nuc.enabled = s.thermal_nuc;
  f.thermal_nuc.average_frames = s.thermal_nuc_frames;
  if (s.wavelet == "legall53") {
    f.fusion.wavelet = vision::Wavelet::kLeGall53;
  } else if (s.wavelet == "cdf97") {
    f.fusion.wavelet = vision::Wavelet::kCdf97;
  } else {
    f.fusion.wavelet = vision::Wavelet::kHaar;
  }
  f.fusion.noise_weighted = s.fusion_noise_weighted;
  f.fusion.denoise = s.fusion_denoise;
  f.fusion.denoise_target_sigma = s.fusion_denoise_target_sigma;
  f.tracker.max_features = s.max_features;
  f.tracker.min_distance_px = s.min_feature_distance_px;
  f.tracker.ransac_threshold_px = s.ransac_threshold_px;
  f.tracker.ransac_max_iterations = s.ransac_max_iterations;
  f.tracker.max_forward_backward_px = s.forward_backward_px;
  f.tracker.klt_window_px = s.klt_window_px;
  f.tracker.klt_pyramid_levels = s.klt_pyramid_levels;
  f.tracker.corner_noise_factor = s.corner_noise_factor;
  f.lines = s.lines;
  f.depth.max_span_m = s.depth_max_span_m;
  f.quality.lambda_n = s.quality_lambda_n;
  f.quality.lambda_g = s.quality_lambda_g;

  c.T_imu_cam = to_isometry(config.extrinsics.T_imu_cam);
  c.T_imu_lidar = to_isometry(config.extrinsics.T_imu_lidar);
  c.has_visible = has_visible;
  c.has_thermal = has_thermal;
  c.pairing.tolerance = Duration::from_seconds(config.sync.pairing_tolerance_s);
  // Live, a frame reaches the core its latency after the IMU samples around its exposure.
  c.arrival_lag =
      in_stamp_order
          ? Duration::from_ns(0)
          : Duration::from_seconds(
                std::max(config.visible_camera.latency_s, config.thermal_camera.latency_s) + 0.05);
  c.depth.window = Duration::from_seconds(s.depth_window_s);
  c.depth.max_points_per_scan = static_cast<std::size_t>(s.depth_points_per_scan);
  const config::DepthCameraSection& d = config.depth_camera;
  c.depth_image.enabled = d.feature_depth;
  c.depth_image.fx = d.fx;
  c.depth_image.fy = d.fy;
  c.depth_image.cx = d.cx;
  c.depth_image.cy = d.cy;
  c.depth_image.T_cam_depth = to_isometry(config.extrinsics.T_cam_depth);
  c.depth_image.stride_px = d.feature_stride_px;
  c.depth_image.min_range_m = d.feature_min_range_m;
  c.depth_image.max_range_m = d.feature_max_range_m;
  c.depth_image.max_offset = Duration::from_seconds(d.feature_max_offset_s);
  f.stereo_depth.max_span_m = d.feature_max_span_m;
  f.stereo_depth.min_range_m = d.feature_min_range_m;
  f.stereo_depth.max_range_m = d.feature_max_range_m;
  // Only the aperture weighting reads the patches' shapes: not worked out per feature otherwise.
  f.patch_shapes = config.estimator.camera_aperture_max_ratio > 1;
  return c;
}

fusion::CameraFactorsConfig camera_factors_config(const config::PosedConfig& config,
                                                  const fusion::CameraFrontEndConfig& cameras) {
  const config::EstimatorSection& e = config.estimator;
  fusion::CameraFactorsConfig c;
  if (e.camera_coupling != "off") {
    c.streams[static_cast<std::size_t>(cameras.frontend.mode)] = true;
    for (const vision::FrontendMode m : cameras.compare_modes) {
      // Only visible+thermal adds a run that feeds the estimate; comparison runs do not.
      if (config.frontend.mode == kTwoStreams && m == vision::FrontendMode::kThermal) {
        c.streams[static_cast<std::size_t>(m)] = true;
      }
    }
  }
  c.T_imu_sensor[0] = cameras.T_imu_cam;
  c.T_imu_sensor[2] = cameras.T_imu_cam;
  // Thermal mode's camera: the thermal camera's origin, the visible camera's axes.
  c.T_imu_sensor[1] =
      cameras.T_imu_cam * Eigen::Translation3d(cameras.frontend.T_cam_thermal.translation());
  c.focal_px = 0.5 * (cameras.frontend.visible_camera.fx + cameras.frontend.visible_camera.fy);
  c.pixel_sigma_px = e.camera_pixel_sigma_px;
  c.quality_weighting = e.camera_quality_weighting;
  c.residual_scaling = e.camera_residual_scaling;
  c.thermal_gate_strict = e.camera_thermal_gate_strict;
  c.thermal_standby = e.camera_thermal_standby;
  c.min_confidence = e.camera_min_confidence;
  c.rejoin_confidence = std::max(e.camera_rejoin_confidence, e.camera_min_confidence);
  c.min_gradient = e.camera_min_gradient;
  c.rejoin_gradient = std::max(e.camera_rejoin_gradient, e.camera_min_gradient);
  c.floor_translation_m = e.camera_floor_translation_m;
  c.strong_lidar_floor_translation_m = e.camera_strong_lidar_floor_translation_m;
  c.floor_rotation_rad = e.camera_floor_rotation_deg * M_PI / 180.0;
  c.keyframe_states = std::min(e.camera_keyframe_states, std::max(e.window_size - 1, 1));
  c.motion.still_flow_sigma = e.camera_still_flow_sigma;
  c.motion.aperture_max_ratio = e.camera_aperture_max_ratio;
  c.guess_gate_px = e.camera_guess_gate_px;
  c.weak_lidar_guess_gate_px = e.camera_weak_lidar_guess_gate_px;
  c.coupling = e.camera_coupling == "landmarks"         ? fusion::CameraCoupling::kLandmarks
               : e.camera_coupling == "loose+landmarks" ? fusion::CameraCoupling::kBoth
                                                        : fusion::CameraCoupling::kBetween;
  c.landmarks.gate_px = e.camera_landmark_gate_px;
  c.landmarks.outlier_sigma = e.camera_landmark_outlier_sigma;
  c.landmarks.huber_sigma = e.camera_landmark_huber_sigma;
  return c;
}

}  // namespace posed::pipeline
