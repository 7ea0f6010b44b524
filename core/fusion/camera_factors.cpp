#include "core/fusion/camera_factors.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "core/math/se3.hpp"
#include "core/math/so3.hpp"
#include "core/sync/pose_interpolation.hpp"

namespace posed::fusion {
namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;

constexpr estimator::FactorKind kKinds[3] = {estimator::FactorKind::kVisible,
                                             estimator::FactorKind::kThermal,
                                             estimator::FactorKind::kFused};
/// Frames kept per stream: more than a window of states needs at 15-25 Hz.
constexpr std::size_t kFramesKept = 48;

Pose pose(const imu::ImuState& s) { return Pose{s.stamp, s.p_map_imu_m, s.q_map_imu}; }

Eigen::Isometry3d isometry(const Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = p.q.normalized().toRotationMatrix();
  T.translation() = p.p;
  return T;
}

const vision::ImageQuality& quality_of(const vision::FrontendFrame& f, std::size_t stream) {
  return stream == 0 ? f.quality.visible : stream == 1 ? f.quality.thermal : f.quality.fused;
}

VisualLandmarksConfig landmarks_config(const CameraFactorsConfig& c) {
  VisualLandmarksConfig l = c.landmarks;
  l.focal_px = c.focal_px;
  return l;
}

}  // namespace

CameraFactors::CameraFactors(const CameraFactorsConfig& config)
    : config_(config),
      landmarks_{VisualLandmarks(landmarks_config(config)),
                 VisualLandmarks(landmarks_config(config)),
                 VisualLandmarks(landmarks_config(config))} {
  config_.motion.pixel_sigma = config.pixel_sigma_px / config.focal_px;
  config_.motion.fix_rotation = config.translation_only;
  config_.motion.min_inliers = config.min_observations;
  for (std::size_t i = 0; i < 3; ++i) {
    figures_[i].configured = config.streams[i];
    figures_[i].active = config.streams[i];
    figures_[i].landmarks = config.coupling != CameraCoupling::kBetween;
  }
}

void CameraFactors::gate(std::size_t stream, double confidence, double gradient) {
  Stream& s = streams_[stream];
  VisualStreamFigures& f = figures_[stream];
  const bool poor = confidence < config_.min_confidence || gradient < config_.min_gradient;
  const bool good = confidence >= config_.rejoin_confidence && gradient >= config_.rejoin_gradient;
  s.below = poor ? s.below + 1 : 0;
  s.above = good ? s.above + 1 : 0;
  if (f.active && s.below >= config_.leave_frames) {
    f.active = false;
    ++f.left;
  } else if (!f.active && s.above >= config_.rejoin_frames) {
    f.active = true;
    ++f.rejoined;
  }
}

void CameraFactors::add_frame(vision::FrontendMode mode, const vision::FrontendFrame& frame) {
  const auto stream = static_cast<std::size_t>(mode);
  if (stream >= 3 || !config_.streams[stream]) return;
  VisualStreamFigures& f = figures_[stream];
  ++f.frames;
  const vision::ImageQuality& q = quality_of(frame, stream);
  // Without an assessment (quality off) the stream is taken at face value.
  f.confidence = q.valid ? q.confidence : 1.0;
  f.omega = config_.quality_weighting && q.valid ? q.omega : 1.0;
  f.gradient = q.valid ? q.gradient_metric : 1.0;
  gate(stream, f.confidence, f.gradient);

  Stream& s = streams_[stream];
  if (!s.frames.empty() && frame.stamp <= s.frames.back().stamp) return;  // never reordered
  StoredFrame stored;
  if (s.frames.size() >= kFramesKept) {
    stored = std::move(s.frames.front());  // reuse its vector's capacity
    s.frames.pop_front();
  }
  stored.stamp = frame.stamp;
  stored.omega = f.omega;
  stored.features.clear();
  for (const vision::FrontendFeature& feature : frame.features) {
    // Only features known to move with the world (not fixed to the camera) give its motion.
    if (!feature.verified || feature.track_length < config_.min_track_length) continue;
    stored.features.push_back(
        {feature.id, feature.normalised, feature.depth_m, feature.patch_shape});
  }
  s.frames.push_back(std::move(stored));
}

const CameraFactors::StoredFrame* CameraFactors::frame_before(const Stream& s, HostTime t) const {
  for (auto it = s.frames.rbegin(); it != s.frames.rend(); ++it) {
    if (it->stamp > t) continue;
    return t - it->stamp <= config_.max_frame_age ? &*it : nullptr;
  }
  return nullptr;
}

std::optional<estimator::RelativeMotion> CameraFactors::measure(
    std::size_t stream, const estimator::SlidingWindow& window, std::size_t k,
    const imu::ImuState& next, bool count_failure) {
  VisualStreamFigures& f = figures_[stream];
  const imu::ImuState before_k = window.state(k - 1);
  const imu::ImuState at_k = window.state(k);
  const imu::ImuState i = window.latest();
  const StoredFrame* a = frame_before(streams_[stream], at_k.stamp);
  const StoredFrame* b = frame_before(streams_[stream], next.stamp);
  if (a == nullptr || b == nullptr || b->stamp <= a->stamp || a->stamp < before_k.stamp) {
    f.no_frames += count_failure ? 1 : 0;
    return std::nullopt;
  }
  // base_link at the two frames' stamps, from the window's motion around them.
  const std::optional<Pose> at_a = interpolate_pose(pose(before_k), pose(at_k), a->stamp);
  const std::optional<Pose> at_b = interpolate_pose(pose(i), pose(next), b->stamp);
  if (!at_a || !at_b) {
    f.no_frames += count_failure ? 1 : 0;
    return std::nullopt;
  }
  const Eigen::Isometry3d T_map_a = isometry(*at_a), T_map_b = isometry(*at_b);
  const Eigen::Isometry3d& T_imu_s = config_.T_imu_sensor[stream];
  const Eigen::Isometry3d predicted_a_b = T_map_a.inverse() * T_map_b;  // base_link, a to b
  FrameMotionConfig motion_config = config_.motion;
  motion_config.gate_falls_back = stream == 0 || !config_.thermal_gate_strict;  // 0: visible
  motion_config.guess_gate =
      (lidar_weak_ ? config_.weak_lidar_guess_gate_px : config_.guess_gate_px) / config_.focal_px;
  const FrameMotion m = estimate_frame_motion(
      a->features, b->features, T_imu_s.inverse() * predicted_a_b * T_imu_s, motion_config);
  if (!m.ok()) {
    f.failed += count_failure ? 1 : 0;
    return std::nullopt;
  }
  const Eigen::Isometry3d measured_a_b = T_imu_s * m.T_a_b * T_imu_s.inverse();
  const Eigen::Isometry3d disagreement = predicted_a_b.inverse() * measured_a_b;
  if (disagreement.translation().norm() > config_.max_disagreement_m ||
      so3::log(Eigen::Matrix3d(disagreement.linear())).norm() > config_.max_disagreement_rad) {
    f.implausible += count_failure ? 1 : 0;
    return std::nullopt;
  }
  f.inliers = m.inliers;
  f.still = m.still;
  f.reprojection_rms_px = m.rms_sigma * config_.pixel_sigma_px;
  // T_k_j = (T_k⁻¹ T_a) M (T_b⁻¹ T_j); the measurement's perturbation moves through the
  // extrinsic and the bridge to state j (right perturbations: Ad of the inverse bridge).
  const Eigen::Isometry3d bridge_b_j = T_map_b.inverse() * imu::T_map_imu(next);
  estimator::RelativeMotion motion;
  motion.kind = kKinds[stream];
  motion.from_index = k;
  motion.T_k_j = imu::T_map_imu(at_k).inverse() * T_map_a * measured_a_b * bridge_b_j;
  motion.T_i_j = imu::T_map_imu(i).inverse() * imu::T_map_imu(at_k) * motion.T_k_j;
  const Mat6 A = se3::adjoint(bridge_b_j.inverse()) * se3::adjoint(T_imu_s);
  const double omega = std::max(a->omega, b->omega) * residual_scale_[stream];
  Mat6 covariance = omega * A * m.covariance * A.transpose();
  const double floor_m = !lidar_weak_ && lidar_settled_ ? config_.strong_lidar_floor_translation_m
                                                        : config_.floor_translation_m;
  covariance.diagonal().tail<3>().array() += floor_m * floor_m;
  if (config_.translation_only) {
    // The rotation was the window's: only the translation is the cameras' information.
    motion.information.setZero();
    motion.information.bottomRightCorner<3, 3>() =
        covariance.bottomRightCorner<3, 3>().ldlt().solve(Eigen::Matrix3d::Identity());
  } else {
    covariance.diagonal().head<3>().array() +=
        config_.floor_rotation_rad * config_.floor_rotation_rad;
    motion.information = covariance.ldlt().solve(Mat6::Identity());
  }
  motion.information = 0.5 * (motion.information + motion.information.transpose());
  motion.huber_sigma = config_.huber_sigma;
  return motion;
}

void CameraFactors::relative_motions(const estimator::SlidingWindow& window,
                                     const imu::ImuState& next,
                                     std::vector<estimator::RelativeMotion>& out) {
  if (window.size() < 2) return;  // the frame before a state needs the state before it
  const std::size_t newest = window.size() - 1;
  for (std::size_t stream = 0; stream < 3; ++stream) {
    if (!config_.streams[stream]) continue;
    VisualStreamFigures& f = figures_[stream];
    std::optional<HostTime>& keyframe = keyframe_stamp_[stream];
    if (!f.active) {
      ++f.gated_out;
      keyframe.reset();
      continue;
    }
    if (standing_by(stream)) {
      ++f.standby;
      keyframe.reset();
      thermal_gave_motion_ = false;
      continue;
    }
    // Landmarks alone: no frame-pair motion, not even for the checks (lidar reconciled, initial
    // value): on corridor seeds 17 and 20-22 the motions' initial values and the landmarks
    // disagreed, and the runs ended further off (18.3 m on seed 20 against 0.89 m without).
    if (config_.coupling == CameraCoupling::kLandmarks) continue;
    // The keyframe's index in the window, if it is still there with the state before it.
    std::optional<std::size_t> k;
    for (std::size_t idx = 1; keyframe && idx < newest; ++idx) {
      if (window.state(idx).stamp == *keyframe) k = idx;
    }
    std::optional<estimator::RelativeMotion> motion;
    if (k && lidar_weak_) motion = measure(stream, window, *k, next, false);
    if (!motion) {  // no keyframe, or too few of its features left: the newest state starts one
      k = newest;
      keyframe = window.state(newest).stamp;
      motion = measure(stream, window, newest, next, true);
    }
    if (motion) {
      out.push_back(*motion);
      if (stream == 1) thermal_gave_motion_ = true;
      ++f.factors;
      if (*k < newest) ++f.keyframe_factors;
    }
    // The new state anchors the next motions once this keyframe is keyframe_states old.
    if (!lidar_weak_ ||
        newest + 1 - *k >= static_cast<std::size_t>(std::max(config_.keyframe_states, 1))) {
      keyframe = next.stamp;
    }
  }
}

bool CameraFactors::standing_by(std::size_t stream) const {
  if (stream != 1 || !config_.thermal_standby) return false;
  for (const std::size_t other : {std::size_t{0}, std::size_t{2}}) {
    if (config_.streams[other] && figures_[other].active) return true;
  }
  return false;
}

bool CameraFactors::active() const {
  for (std::size_t stream = 0; stream < 3; ++stream) {
    if (!config_.streams[stream] || !figures_[stream].active) continue;
    if (stream == 1 && config_.thermal_standby) {
      // Standing in, it counts once it gives motions: the lidar keeps its say along directions
      // it cannot pin until then (on the corridor its gate stays open while every pair fails).
      if (standing_by(stream) || !thermal_gave_motion_) continue;
    }
    return true;
  }
  return false;
}

std::uint8_t CameraFactors::add_factors(estimator::SlidingWindow& window) {
  if (config_.coupling == CameraCoupling::kBetween || window.size() < 2) return 0;
  constexpr std::uint8_t kBits[3] = {kModalityVisible, kModalityThermal, kModalityFused};
  const std::size_t newest = window.size() - 1;
  std::uint8_t modalities = 0;
  for (std::size_t stream = 0; stream < 3; ++stream) {
    if (!config_.streams[stream]) continue;
    if (!figures_[stream].active || standing_by(stream)) {
      landmarks_[stream].clear();
      continue;
    }
    // Each state observes from the last frame at or before its stamp and after the previous
    // state's. A frame reaches the back end some time after its stamp (the front end waits for
    // the IMU past it, the camera's transport is slower than the lidar's), so the frame of the
    // state before the newest may have come only now: it is that state's observation, late.
    for (std::size_t k = newest - 1; k <= newest; ++k) {
      if (k == 0 || window.id(k) <= observed_id_[stream]) continue;
      const imu::ImuState before = window.state(k - 1);
      const imu::ImuState at = window.state(k);
      const StoredFrame* frame = frame_before(streams_[stream], at.stamp);
      if (frame == nullptr || frame->stamp < before.stamp) {
        // The newest state's frame may still come; the one before has had its second chance.
        if (k < newest) ++figures_[stream].no_frames;
        continue;
      }
      if (k < newest && frame->stamp <= observed_stamp_[stream]) continue;  // used already
      observed_id_[stream] = window.id(k);
      observed_stamp_[stream] = frame->stamp;
      // The camera of the frame in state k's body: the bridge from the frame's stamp to the
      // state's, from the window's motion between state k and the one before.
      const std::optional<Pose> at_frame = interpolate_pose(pose(before), pose(at), frame->stamp);
      if (!at_frame) continue;
      const Eigen::Isometry3d T_body_cam =
          imu::T_map_imu(at).inverse() * isometry(*at_frame) * config_.T_imu_sensor[stream];
      const double omega = frame->omega * residual_scale_[stream];
      const double sqrt_information =
          config_.focal_px / (config_.pixel_sigma_px * std::sqrt(omega));
      const int added = landmarks_[stream].add(window, k, kKinds[stream], frame->features,
                                               T_body_cam, sqrt_information);
      VisualStreamFigures& f = figures_[stream];
      const VisualLandmarksFigures& l = landmarks_[stream].figures();
      f.factors += static_cast<std::uint64_t>(added);
      f.landmarks_anchored = l.anchored;
      f.landmarks_still = l.still;
      f.landmarks_gated = l.gated;
      f.landmarks_tracked = landmarks_[stream].tracked();
      if (added > 0) modalities |= kBits[stream];
    }
  }
  return modalities;
}

void CameraFactors::after_solve(const estimator::SlidingWindow& window) {
  if (config_.coupling != CameraCoupling::kBetween) {
    for (std::size_t s = 0; s < 3; ++s) {
      if (!config_.streams[s]) continue;
      landmarks_[s].after_solve(window);
      figures_[s].landmarks_outliers = landmarks_[s].figures().outliers;
    }
  }
  std::array<double, 3> unscaled{};  // medians whitened at Σ_base ω, before the residual scale
  std::array<bool, 3> have{};
  for (std::size_t stream = 0; stream < 3; ++stream) {
    if (!config_.streams[stream]) continue;
    window.residual_norms(kKinds[stream], residuals_);
    if (residuals_.empty()) continue;
    auto mid = residuals_.begin() + static_cast<std::ptrdiff_t>(residuals_.size() / 2);
    std::nth_element(residuals_.begin(), mid, residuals_.end());
    figures_[stream].residual_median = *mid;
    unscaled[stream] = *mid * std::sqrt(residual_scale_[stream]);
    have[stream] = true;
  }
  if (!config_.residual_scaling) return;
  // Streams are weighed against each other, not against the lidar: with one stream (or where
  // every stream disagrees with a lidar that aliases) nothing changes. A stream whose factors sit
  // k times further from the solution than the best stream's gets k² its covariance, reached
  // slowly (5 % per solve, geometrically) so one poor window does not swing the weights.
  double best = 0;
  for (std::size_t s = 0; s < 3; ++s) {
    if (have[s] && (best == 0 || unscaled[s] < best)) best = unscaled[s];
  }
  if (best <= 0) return;
  constexpr double kRate = 0.05;
  for (std::size_t s = 0; s < 3; ++s) {
    if (!have[s]) continue;
    const double target =
        std::clamp((unscaled[s] / best) * (unscaled[s] / best), 1.0, config_.residual_scale_max);
    residual_scale_[s] *= std::pow(target / residual_scale_[s], kRate);
    figures_[s].residual_scale = residual_scale_[s];
  }
}

}  // namespace posed::fusion
