#include "core/vision/visual_frontend.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/vision/image_view.hpp"
#include "core/vision/patch_shape.hpp"

namespace posed::vision {

std::string_view to_string(FrontendMode mode) {
  switch (mode) {
    case FrontendMode::kVisible:
      return "visible";
    case FrontendMode::kThermal:
      return "thermal";
    case FrontendMode::kFused:
      return "fused";
  }
  return "unknown";
}

std::string_view to_string(FrontendStatus status) {
  switch (status) {
    case FrontendStatus::kOk:
      return "ok";
    case FrontendStatus::kVisibleUnusable:
      return "visible image unusable";
    case FrontendStatus::kThermalUnusable:
      return "thermal image unusable";
  }
  return "unknown";
}

FrontendInput make_input(const Image* visible, const Image* thermal) {
  FrontendInput input;
  if (visible != nullptr) {
    input.visible_stamp = visible->stamp;
    input.visible = view(*visible);
    input.visible_rgb = visible->format == PixelFormat::kRgb8;
  }
  if (thermal != nullptr) {
    input.thermal_stamp = thermal->stamp;
    input.thermal = view(*thermal);
  }
  return input;
}

namespace {
const FrontendConfig& checked(const FrontendConfig& config) {
  if (!config.visible_camera.valid() ||
      (config.mode != FrontendMode::kVisible && !config.thermal_camera.valid())) {
    throw std::invalid_argument("visual front end: camera intrinsics missing or invalid");
  }
  return config;
}
}  // namespace

VisualFrontend::VisualFrontend(const FrontendConfig& config)
    : config_(checked(config)),
      visible_enhancer_(config.visible_enhance),
      thermal_enhancer_(config.thermal_enhance),
      thermal_nuc_(config.thermal_nuc),
      fusion_(config.fusion),
      quality_(config.quality),
      tracker_(config.tracker, config.visible_camera),
      line_tracker_(config.line),
      depth_(config.depth, config.visible_camera),
      stereo_depth_(config.stereo_depth, config.visible_camera) {
  if (config.mode != FrontendMode::kVisible) {
    aligner_ = std::make_unique<ThermalAligner>(config.visible_camera, config.thermal_camera,
                                                config.T_cam_thermal, config.thermal_align);
  }
}

VisualFrontend::~VisualFrontend() = default;

const cv::Mat& VisualFrontend::tracked_grey() const {
  switch (config_.mode) {
    case FrontendMode::kVisible:
      return visible_grey_;
    case FrontendMode::kThermal:
      return thermal_grey_;
    case FrontendMode::kFused:
      break;
  }
  return fused_grey_;
}

FrontendStatus VisualFrontend::process(const FrontendInput& input, FrontendFrame& out) {
  const FrontendMode mode = config_.mode;
  const bool use_visible = mode != FrontendMode::kThermal;
  const bool use_thermal = mode != FrontendMode::kVisible;
  out.mode = mode;
  out.features.clear();
  out.lines.clear();
  out.quality = {};
  out.counts = {};
  out.thermal_alignment = {};
  out.thermal_nuc = {};
  out.visible_gamma = 1;
  out.stamp = mode == FrontendMode::kThermal ? input.thermal_stamp : input.visible_stamp;

  const PinholeCamera& camera = config_.visible_camera;
  if (use_visible && (input.visible.cols != camera.width || input.visible.rows != camera.height ||
                      (input.visible.type() != CV_8UC3 && input.visible.type() != CV_8UC1))) {
    return out.status = FrontendStatus::kVisibleUnusable;
  }
  if (use_thermal && input.thermal.empty()) return out.status = FrontendStatus::kThermalUnusable;
  // The thermal frame as every later step sees it: without its fixed pattern when NUC is on.
  const cv::Mat* thermal = &input.thermal;

  if (use_visible) {
    begin(FrontendStep::kEnhance);
    out.visible_gamma =
        visible_enhancer_.enhance_to_grey(input.visible, input.visible_rgb, visible_grey_).gamma;
    end(FrontendStep::kEnhance);
  } else {
    visible_grey_.release();
  }

  cv::Mat detect_mask;
  if (use_thermal) {
    begin(FrontendStep::kThermal);
    if (config_.thermal_nuc.enabled) {
      out.thermal_nuc = thermal_nuc_.correct(input.thermal, thermal_corrected_);
      thermal = &thermal_corrected_;
    }
    // Thermal-only tracking has no visible stamp to compensate to.
    const Eigen::Matrix3d R =
        mode == FrontendMode::kFused ? input.R_camtv_camtt : Eigen::Matrix3d::Identity();
    // Depth-aware registration (kLidarDepth) only for the fusion, which needs the thermal image
    // on the visible one pixel for pixel. Tracked alone, the thermal image registered at infinity
    // is the thermal camera's own view through a pure rotation; a warp by a per-frame lidar depth
    // grid would only add distortion that changes from frame to frame.
    const std::span<const Eigen::Vector3f> points =
        mode == FrontendMode::kFused ? input.p_cam_m : std::span<const Eigen::Vector3f>();
    const bool aligned =
        aligner_->align(*thermal, R, thermal_aligned_, out.thermal_alignment, points);
    if (aligned) {
      if (config_.thermal_enhance.enabled) {
        thermal_enhancer_.enhance_to_grey(thermal_aligned_, false, thermal_grey_);
      } else {
        thermal_grey_ = thermal_aligned_;
      }
      if (out.thermal_alignment.invalid_pixels > 0) {
        if (mode == FrontendMode::kFused) {
          // Where the thermal camera sees nothing, fuse the visible image with itself: eq. (7)
          // and (8) then return it unchanged, and no seam is made for the tracker to follow.
          cv::Mat missing;
          cv::bitwise_not(aligner_->valid_mask(), missing);
          visible_grey_.copyTo(thermal_grey_, missing);
        } else {
          // Corners on the edge of what the thermal lens covers hold still in the image however
          // the camera moves: keep new corners a KLT window away from it.
          const int margin = config_.tracker.klt_window_px;
          cv::erode(
              aligner_->valid_mask(), thermal_detect_mask_,
              cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * margin + 1, 2 * margin + 1)));
          detect_mask = thermal_detect_mask_;
        }
      }
    }
    end(FrontendStep::kThermal);
    if (!aligned) return out.status = FrontendStatus::kThermalUnusable;
  } else {
    thermal_grey_.release();
  }

  // Quality of the input streams first: the noise-weighted fusion needs their noise levels.
  const bool fused = mode == FrontendMode::kFused;
  if (config_.assess_quality || (fused && config_.fusion.noise_weighted)) {
    begin(FrontendStep::kQuality);
    // Each stream at its native resolution: the thermal on its raw pixels (resampling would hide
    // its noise from the estimator, see image_quality.hpp).
    if (use_visible) out.quality.visible = quality_.assess(visible_grey_);
    if (use_thermal) {
      // For 8-bit frames this is a view of the caller's buffer: enhance into our own.
      aligner_->native_grey(*thermal, out.thermal_alignment, thermal_native_);
      if (config_.thermal_enhance.enabled) {
        thermal_enhancer_.enhance_to_grey(thermal_native_, false, thermal_native_enhanced_);
        out.quality.thermal = quality_.assess(thermal_native_enhanced_);
      } else {
        out.quality.thermal = quality_.assess(thermal_native_);
      }
    }
    end(FrontendStep::kQuality);
  }

  if (fused) {
    // The registered thermal image is the native one upsampled by visible width / crop width;
    // bilinear upsampling by 1/s scales white noise by about s (0.67 measured for s = 0.71).
    const double thermal_scale =
        aligner_->source_roi().width / static_cast<double>(config_.visible_camera.width);
    double visible_noise = out.quality.visible.valid ? out.quality.visible.noise_sigma : 0;
    double thermal_noise =
        out.quality.thermal.valid ? out.quality.thermal.noise_sigma * thermal_scale : 0;
    begin(FrontendStep::kFusion);
    const cv::Mat* visible_in = &visible_grey_;
    const cv::Mat* thermal_in = &thermal_grey_;
    if (config_.fusion.denoise) {
      const FusionConfig& f = config_.fusion;
      visible_noise = denoise_gaussian(visible_grey_, visible_noise, f.denoise_target_sigma,
                                       f.denoise_max_sigma_px, visible_denoised_);
      thermal_noise = denoise_gaussian(thermal_grey_, thermal_noise, f.denoise_target_sigma,
                                       f.denoise_max_sigma_px, thermal_denoised_);
      visible_in = &visible_denoised_;
      thermal_in = &thermal_denoised_;
    }
    fusion_.fuse(*visible_in, *thermal_in, fused_grey_, visible_noise, thermal_noise);
    end(FrontendStep::kFusion);
    if (config_.assess_quality) {
      begin(FrontendStep::kQuality);
      // The fused image holds resampled thermal detail, whose noise the estimator underrates:
      // bound it below by the noise of the source its flat regions come from (the quieter one
      // with the noise-weighted rule, the noisier one with eq. (8) as published).
      const double floor = config_.fusion.noise_weighted ? std::min(visible_noise, thermal_noise)
                                                         : std::max(visible_noise, thermal_noise);
      out.quality.fused = quality_.assess(fused_grey_, floor);
      end(FrontendStep::kQuality);
    }
  } else {
    fused_grey_.release();
  }

  begin(FrontendStep::kTracking);
  const cv::Mat& tracked = tracked_grey();
  const TrackStats stats = tracker_.track(tracked, detect_mask);
  if (config_.lines) {
    line_tracker_.track(tracked);
    out.lines = line_tracker_.lines();
  }
  end(FrontendStep::kTracking);

  begin(FrontendStep::kDepth);
  const bool lidar = !input.p_cam_m.empty();
  if (lidar) depth_.set_points(input.p_cam_m);
  const bool stereo = !input.p_depth_cam_m.empty();
  if (stereo) stereo_depth_.set_points(input.p_depth_cam_m);
  const double dt = has_previous_ ? (out.stamp - previous_stamp_).seconds() : 0.0;
  std::size_t previous_index = 0;
  for (const Track& t : tracker_.tracks()) {
    FrontendFeature f;
    f.id = t.id;
    f.pixel_px = {t.pixel.x, t.pixel.y};
    f.normalised = t.normalised;
    f.track_length = t.length;
    if (config_.patch_shapes) {
      f.patch_shape = patch_shape(tracked, t.pixel, config_.tracker.klt_window_px / 2);
    }
    if (lidar) {
      const DepthResult d = depth_.depth(t.normalised);
      f.depth_m = d.depth_m;
      f.depth_status = d.status;
      if (d.status == DepthStatus::kOk) ++out.counts.depth_associated;
    }
    if (stereo && !std::isfinite(f.depth_m)) {
      const DepthResult d = stereo_depth_.depth(t.normalised);
      if (d.status == DepthStatus::kOk) {
        f.depth_m = d.depth_m;
        f.depth_status = d.status;
        f.depth_from_stereo = true;
        ++out.counts.depth_associated;
        ++out.counts.stereo_depth_associated;
      }
    }
    // Both lists are in id order: walk the previous one alongside.
    while (previous_index < previous_.size() && previous_[previous_index].first < t.id) {
      ++previous_index;
    }
    if (dt > 0 && previous_index < previous_.size() && previous_[previous_index].first == t.id) {
      f.velocity_per_s = (t.normalised - previous_[previous_index].second) / dt;
    }
    out.features.push_back(f);
  }
  out.counts.lidar_points = lidar ? static_cast<int>(depth_.tree_points()) : 0;
  out.counts.stereo_points = stereo ? static_cast<int>(stereo_depth_.tree_points()) : 0;
  end(FrontendStep::kDepth);

  previous_.clear();
  for (const FrontendFeature& f : out.features) previous_.emplace_back(f.id, f.normalised);
  previous_stamp_ = out.stamp;
  has_previous_ = true;

  out.counts.previous = stats.previous;
  out.counts.tracked = stats.klt_tracked;
  out.counts.ransac_inliers = stats.ransac_inliers;
  out.counts.crowded = stats.crowded;
  out.counts.extracted = stats.extracted;
  out.counts.features = static_cast<int>(out.features.size());
  out.counts.lines = static_cast<int>(out.lines.size());
  return out.status = FrontendStatus::kOk;
}

}  // namespace posed::vision
