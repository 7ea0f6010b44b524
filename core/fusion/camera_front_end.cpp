#include "core/fusion/camera_front_end.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "core/fusion/gyro_rotation.hpp"

namespace posed::fusion {

namespace {

constexpr std::size_t kImuCapacity = 2000;  // > 10 s at 150-200 Hz: covers any frame latency
constexpr std::size_t kPoseCapacity = 2048;

DepthCloudConfig depth_config(const CameraFrontEndConfig& c) {
  DepthCloudConfig d = c.depth;
  // The camera's optical axis (z) in the lidar frame.
  d.view_axis_lidar = (c.T_imu_lidar.linear().transpose() * c.T_imu_cam.linear()).col(2);
  return d;
}

StreamQualityFigures quality_figures(const vision::ImageQuality& q) {
  return {q.valid, q.gradient_metric, q.noise_sigma, q.confidence, q.omega};
}

}  // namespace

CameraFrontEnd::CameraFrontEnd(const CameraFrontEndConfig& config)
    : config_(config),
      pairer_(config.pairing),
      imu_(ImuBufferConfig{.capacity = kImuCapacity}),
      poses_(
          PoseHistoryConfig{.capacity = kPoseCapacity, .max_extrapolation = Duration::from_ms(50)}),
      depth_(depth_config(config)) {
  scratch_.reserve(imu_.capacity());
  std::vector<vision::FrontendMode> modes{config.frontend.mode};
  modes.insert(modes.end(), config.compare_modes.begin(), config.compare_modes.end());
  for (const vision::FrontendMode mode : modes) {
    vision::FrontendConfig c = config.frontend;
    c.mode = mode;
    Run run;
    run.frontend = std::make_unique<vision::VisualFrontend>(c);
    StaticTrackConfig st = config.static_tracks;
    st.focal_px = 0.5 * (c.visible_camera.fx + c.visible_camera.fy);
    run.static_tracks = std::make_unique<StaticTrackFilter>(st);
    run.figures.mode = vision::to_string(mode);
    runs_.push_back(std::move(run));
  }
}

CameraFrontEnd::~CameraFrontEnd() = default;

void CameraFrontEnd::add_imu(const ImuSample& sample) { imu_.push(sample); }

void CameraFrontEnd::add_state(const NavState& state) {
  // Propagated and optimised states interleave out of stamp order (an optimised state lands on
  // a scan's end, behind the propagation); the history keeps the stamp-ordered ones, which is
  // all the depth cloud needs (its points tolerate centimetres).
  poses_.push(Pose{state.stamp, state.p_map_base_m, state.q_map_base});
}

void CameraFrontEnd::add_scan(const MatchedScan& scan) {
  if (scan.index == last_scan_index_) return;
  last_scan_index_ = scan.index;
  depth_.add_scan(scan.stamp, scan.T_map_lidar, scan.points_lidar);
}

void CameraFrontEnd::add_image(CameraStream stream, Image image) {
  if (stream == CameraStream::kDepth) {
    if (!config_.depth_image.enabled || image.format != PixelFormat::kDepth16) return;
    // Frame events trail the depth images by the IMU's cover of their stamps (a few samples);
    // a few images span that, and each holds a pool buffer of the depth camera stage.
    constexpr std::size_t kDepthImagesHeld = 3;
    depth_images_.push_back(std::move(image));
    while (depth_images_.size() > kDepthImagesHeld) depth_images_.pop_front();
    return;
  }
  if (stream == CameraStream::kVisible) {
    pairer_.push_visible(std::move(image));
  } else {
    pairer_.push_thermal(std::move(image));
  }
}

void CameraFrontEnd::process(const Eigen::Vector3d& gyro_bias_radps) {
  std::optional<HostTime> watermark;
  if (!imu_.empty()) watermark = imu_.newest_stamp() - config_.arrival_lag;
  while (auto released = pairer_.pop(watermark)) {
    if (!released->visible && config_.has_visible) continue;  // a thermal frame nobody pairs
    Event e;
    e.stamp = released->visible ? released->visible->stamp : released->thermal->stamp;
    e.latest = e.stamp;
    if (released->thermal) e.latest = std::max(e.latest, released->thermal->stamp);
    e.visible = std::move(released->visible);
    e.thermal = std::move(released->thermal);
    ready_.push_back(std::move(e));
  }
  while (!ready_.empty() && imu_.covers(ready_.front().latest)) {
    run_event(ready_.front(), gyro_bias_radps);
    ready_.pop_front();
  }
  // Events the IMU can no longer cover (it jumped past them, or restarted) would wait forever.
  while (ready_.size() > 2 * config_.pairing.pending_capacity) {
    for (Run& run : runs_) ++run.figures.frames_without_imu;
    ready_.pop_front();
  }
  if (!imu_.empty()) imu_.discard_before(imu_.newest_stamp() - Duration::from_s(2));
}

namespace {

/// A 64-bit hash of an image's rows, to tell a repeated frame from a new one. FNV-1a's step on
/// 8-byte words in four independent lanes: byte by byte, one multiply waiting for the last, it
/// cost a millisecond per 640x512 16-bit thermal frame. A word that differs always changes its
/// lane, and the lanes are folded so that a changed lane always changes the hash.
std::uint64_t image_hash(const Image& image) {
  constexpr std::uint64_t kPrime = 1099511628211ull;
  const std::span<const std::byte> bytes = image.pixels.bytes();
  const std::size_t size =
      std::min(bytes.size(), static_cast<std::size_t>(image.stride) * image.height);
  std::array<std::uint64_t, 4> lane = {1469598103934665603ull, 1469598103934665603ull ^ 1,
                                       1469598103934665603ull ^ 2, 1469598103934665603ull ^ 3};
  std::size_t i = 0;
  for (; i + 32 <= size; i += 32) {
    for (std::size_t k = 0; k < 4; ++k) {
      std::uint64_t word = 0;
      std::memcpy(&word, bytes.data() + i + 8 * k, sizeof word);
      lane[k] = (lane[k] ^ word) * kPrime;
    }
  }
  for (; i < size; ++i) lane[0] = (lane[0] ^ static_cast<std::uint64_t>(bytes[i])) * kPrime;
  std::uint64_t h = lane[0];
  for (std::size_t k = 1; k < 4; ++k) h = (h * kPrime) ^ lane[k];
  return h;
}

}  // namespace

void CameraFrontEnd::run_event(Event& e, const Eigen::Vector3d& gyro_bias_radps) {
  // A thermal camera repeats its last frame while its shutter is closed for the flat-field
  // correction (the PLUG 617 for about 0.3 s every minute or two): every feature would hold
  // still while the robot moves. A frame identical to the last is no view of the present.
  if (e.thermal) {
    const std::uint64_t hash = image_hash(*e.thermal);
    const bool frozen = last_thermal_hash_ && *last_thermal_hash_ == hash;
    last_thermal_hash_ = hash;
    if (frozen) {
      e.thermal.reset();
      for (Run& run : runs_) {
        ++run.figures.thermal_frozen;
        run.frontend->thermal_shutter();
      }
    }
  }
  vision::FrontendInput input =
      vision::make_input(e.visible ? &*e.visible : nullptr, e.thermal ? &*e.thermal : nullptr);
  input.visible_stamp = e.visible ? e.visible->stamp : e.stamp;
  input.thermal_stamp = e.thermal ? e.thermal->stamp : e.stamp;
  if (e.visible && e.thermal) {
    const std::optional<Eigen::Matrix3d> R_btv_btt =
        gyro_rotation(imu_, input.visible_stamp, input.thermal_stamp, gyro_bias_radps, scratch_);
    if (!R_btv_btt) {
      for (Run& run : runs_) ++run.figures.frames_without_imu;
      return;
    }
    const Eigen::Matrix3d R_imu_cam = config_.T_imu_cam.linear();
    input.R_camtv_camtt = R_imu_cam.transpose() * *R_btv_btt * R_imu_cam;
  }
  // Depth: the stacked lidar points in the camera frame at the tracked image's stamp, when the
  // estimator has a pose there (none before it is aligned, or without a lidar).
  p_cam_m_.clear();
  p_depth_cam_m_.clear();
  if (const std::optional<Pose> T = poses_.at(e.stamp)) {
    const Eigen::Isometry3d T_map_cam =
        Eigen::Translation3d(T->p) * T->q.normalized() * config_.T_imu_cam;
    if (depth_.scans() > 0) depth_.points_in_camera(e.stamp, T_map_cam, p_cam_m_);
    if (!depth_images_.empty() && depth_image_points(e.stamp, T_map_cam)) {
      for (Run& run : runs_) ++run.figures.depth_images;
    }
  }
  // Thermal mode tracks the thermal image registered at infinity: a camera at the thermal
  // camera's origin with the visible camera's axes, so its features' depth comes from the points
  // seen from there (17 cm to the side on the M2DGR rig: 3 deg of parallax at 3 m).
  p_thermal_origin_m_.clear();
  p_depth_thermal_origin_m_.clear();
  const Eigen::Vector3f t_cam_thermal = config_.frontend.T_cam_thermal.translation().cast<float>();
  for (const Run& run : runs_) {
    if (run.frontend->config().mode != vision::FrontendMode::kThermal) continue;
    for (const Eigen::Vector3f& p : p_cam_m_) p_thermal_origin_m_.push_back(p - t_cam_thermal);
    for (const Eigen::Vector3f& p : p_depth_cam_m_) {
      p_depth_thermal_origin_m_.push_back(p - t_cam_thermal);
    }
    break;
  }
  for (Run& run : runs_) {
    const vision::FrontendMode mode = run.frontend->config().mode;
    const bool thermal = mode == vision::FrontendMode::kThermal;
    input.p_cam_m = thermal ? std::span<const Eigen::Vector3f>(p_thermal_origin_m_)
                            : std::span<const Eigen::Vector3f>(p_cam_m_);
    input.p_depth_cam_m = thermal ? std::span<const Eigen::Vector3f>(p_depth_thermal_origin_m_)
                                  : std::span<const Eigen::Vector3f>(p_depth_cam_m_);
    const bool usable = (mode != vision::FrontendMode::kVisible || e.visible) &&
                        (mode != vision::FrontendMode::kThermal || e.thermal) &&
                        (mode != vision::FrontendMode::kFused || (e.visible && e.thermal));
    if (!usable) {
      ++run.figures.frames_unusable;
      continue;
    }
    const vision::FrontendStatus status = run.frontend->process(input, run.frame);
    if (status == vision::FrontendStatus::kOk) {
      if (config_.drop_static_tracks) {
        drop_static_tracks(run);
      } else {
        for (vision::FrontendFeature& f : run.frame.features) f.verified = true;
      }
    }
    account(run, status);
    if (status != vision::FrontendStatus::kOk) continue;
    if (back_end_ != nullptr) back_end_->on_frame(run.frame, *run.frontend);
    if (observer_ != nullptr) observer_->on_frame(run.frame, *run.frontend);
  }
}

bool CameraFrontEnd::depth_image_points(HostTime stamp, const Eigen::Isometry3d& T_map_cam) {
  const DepthImageConfig& c = config_.depth_image;
  const auto offset_ns = [&](const Image& image) { return std::abs((image.stamp - stamp).ns); };
  const Image* nearest = nullptr;
  for (const Image& image : depth_images_) {
    if (nearest == nullptr || offset_ns(image) < offset_ns(*nearest)) nearest = &image;
  }
  if (nearest == nullptr || offset_ns(*nearest) > c.max_offset.ns) return false;
  // The depth image's camera at its own stamp, seen from the camera at the frame's: the robot
  // moves up to half a depth frame period between them (2-3 cm at walking speed).
  const std::optional<Pose> T_depth_stamp = poses_.at(nearest->stamp);
  if (!T_depth_stamp) return false;
  const Eigen::Isometry3d T_map_depth = Eigen::Translation3d(T_depth_stamp->p) *
                                        T_depth_stamp->q.normalized() * config_.T_imu_cam *
                                        c.T_cam_depth;
  const Eigen::Matrix<float, 3, 4> T_cam_depth_now =
      (T_map_cam.inverse() * T_map_depth).matrix().topRows<3>().cast<float>();
  const std::span<const std::byte> bytes = nearest->pixels.bytes();
  const std::size_t step = static_cast<std::size_t>(std::max(1, c.stride_px));
  const float unit = nearest->depth_unit_m;
  const float min_z = static_cast<float>(c.min_range_m), max_z = static_cast<float>(c.max_range_m);
  const float inv_fx = static_cast<float>(1.0 / c.fx), inv_fy = static_cast<float>(1.0 / c.fy);
  const float cx = static_cast<float>(c.cx), cy = static_cast<float>(c.cy);
  for (std::size_t v = step / 2; v < nearest->height; v += step) {
    const std::size_t row = v * nearest->stride;
    if (row + 2 * static_cast<std::size_t>(nearest->width) > bytes.size()) break;
    for (std::size_t u = step / 2; u < nearest->width; u += step) {
      std::uint16_t raw = 0;
      std::memcpy(&raw, bytes.data() + row + 2 * u, sizeof raw);
      const float z = static_cast<float>(raw) * unit;
      if (raw == 0 || z < min_z || z > max_z) continue;  // 0: no stereo match
      const Eigen::Vector4f p_depth((static_cast<float>(u) - cx) * inv_fx * z,
                                    (static_cast<float>(v) - cy) * inv_fy * z, z, 1.0f);
      p_depth_cam_m_.push_back(T_cam_depth_now * p_depth);
    }
  }
  return !p_depth_cam_m_.empty();
}

void CameraFrontEnd::drop_static_tracks(Run& run) {
  vision::FrontendFrame& frame = run.frame;
  fixed_ids_.clear();
  run.static_tracks->update(frame.features, fixed_ids_);
  if (fixed_ids_.empty()) return;
  run.frontend->drop_tracks(fixed_ids_);
  std::erase_if(frame.features, [&](const vision::FrontendFeature& f) {
    return std::binary_search(fixed_ids_.begin(), fixed_ids_.end(), f.id);
  });
  run.figures.static_dropped_total += fixed_ids_.size();
  frame.counts.features = static_cast<int>(frame.features.size());
  frame.counts.depth_associated = static_cast<int>(
      std::count_if(frame.features.begin(), frame.features.end(),
                    [](const vision::FrontendFeature& f) { return std::isfinite(f.depth_m); }));
  frame.counts.stereo_depth_associated = static_cast<int>(
      std::count_if(frame.features.begin(), frame.features.end(),
                    [](const vision::FrontendFeature& f) { return f.depth_from_stereo; }));
}

void CameraFrontEnd::account(Run& run, vision::FrontendStatus status) {
  CameraFigures& f = run.figures;
  if (status != vision::FrontendStatus::kOk) {
    ++f.frames_unusable;
    return;
  }
  const vision::FrontendFrame& frame = run.frame;
  ++f.frames;
  f.previous_total += static_cast<std::uint64_t>(frame.counts.previous);
  f.inliers_total += static_cast<std::uint64_t>(frame.counts.ransac_inliers);
  f.extracted_total += static_cast<std::uint64_t>(frame.counts.extracted);
  f.features_total += static_cast<std::uint64_t>(frame.counts.features);
  f.depth_total += static_cast<std::uint64_t>(frame.counts.depth_associated);
  f.stereo_depth_total += static_cast<std::uint64_t>(frame.counts.stereo_depth_associated);
  f.features = frame.counts.features;
  f.depth_associated = frame.counts.depth_associated;
  f.lidar_points = frame.counts.lidar_points;
  const vision::ImageQuality* q[3] = {&frame.quality.visible, &frame.quality.thermal,
                                      &frame.quality.fused};
  for (std::size_t i = 0; i < 3; ++i) {
    f.quality[i] = quality_figures(*q[i]);
    if (!q[i]->valid) continue;
    ++f.quality_frames[i];
    // Running mean, exact for any count.
    f.mean_confidence[i] +=
        (q[i]->confidence - f.mean_confidence[i]) / static_cast<double>(f.quality_frames[i]);
  }
}

std::vector<CameraFigures> CameraFrontEnd::compare_figures() const {
  std::vector<CameraFigures> out;
  for (std::size_t i = 1; i < runs_.size(); ++i) out.push_back(runs_[i].figures);
  return out;
}

}  // namespace posed::fusion
