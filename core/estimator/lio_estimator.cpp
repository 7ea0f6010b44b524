#include "core/estimator/lio_estimator.hpp"

#include <ceres/loss_function.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <span>

#include "core/estimator/factors.hpp"
#include "core/estimator/match_retry.hpp"
#include "core/math/so3.hpp"

namespace posed::estimator {
namespace {

SlidingWindowConfig window_config(const LioConfig& c) {
  SlidingWindowConfig w = c.window;
  w.gravity_mps2 = c.gravity_mps2;
  w.T_imu_lidar = c.T_imu_lidar;
  return w;
}

/// The covariance of an information matrix that may be singular (a direction nothing measured
/// gets a variance of 1e9).
Eigen::Matrix<double, 6, 6> covariance_of(const Eigen::Matrix<double, 6, 6>& information) {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  return (information + 1e-9 * Mat6::Identity()).ldlt().solve(Mat6::Identity());
}

/// The scan says nothing along `directions` (unit translations in the lidar frame, the axes of
/// its information's translation block): that information is projected onto their complement.
/// The rotation and the other translations keep theirs.
void drop_translations(LidarPose& lidar, std::span<const Eigen::Vector3d> directions) {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  Mat6 P = Mat6::Identity();
  for (const Eigen::Vector3d& e : directions) P.block<3, 3>(3, 3) -= e * e.transpose();
  lidar.information = P * lidar.information * P.transpose();
}

}  // namespace

LioEstimator::LioEstimator(const LioConfig& config)
    : config_(config),
      alignment_(config.alignment),
      moving_alignment_(imu::MovingAlignmentConfig{.gravity_mps2 = config.gravity_mps2}),
      // 20 s at 200 Hz: room for the lag of the slowest scan and a stalled consumer.
      imu_(ImuBufferConfig{.capacity = 4000}),
      gate_(MeasurementGateConfig{.pending_capacity = kLidarScanGateCapacity}),
      lidar_(config.lidar),
      map_cloud_(config.map_voxel_m),
      window_(window_config(config)) {
  bundle_imu_.reserve(imu_.capacity());
  scratch_.reserve(imu_.capacity());
}

FusionFigures LioEstimator::figures() const {
  FusionFigures f = figures_;
  f.keyframes = lidar_.counters().keyframes;
  f.gravity_tilt_estimated = config_.window.estimate_gravity_tilt;
  if (anchor_) {
    f.gyro_bias_radps = anchor_->bias.gyro_radps;
    f.accel_bias_mps2 = anchor_->bias.accel_mps2;
    f.gravity_tilt_rad = window_.gravity_tilt();
    f.heading_span_rad = window_.heading_span_rad();
    f.window_solves = window_.counters().solves;
    f.window_solves_tilt_free = window_.counters().solves_tilt_free;
  } else if (aligned_) {
    f.gyro_bias_radps = aligned_->gyro_bias_radps;
  }
  return f;
}

NavState LioEstimator::to_nav_state(const imu::ImuState& s, const Eigen::Vector3d& w_body,
                                    bool optimised, const Eigen::Matrix<double, 6, 6>& cov) const {
  NavState out;
  out.stamp = s.stamp;
  out.p_map_base_m = s.p_map_imu_m;
  out.q_map_base = s.q_map_imu;
  out.v_map_mps = s.v_map_mps;
  out.w_base_radps = w_body;
  // Tangent [dp map, dtheta body] to ROS order (position, rotation about map-fixed axes).
  const Eigen::Matrix3d R = s.q_map_imu.toRotationMatrix();
  out.pose_covariance.topLeftCorner<3, 3>() = cov.topLeftCorner<3, 3>();
  out.pose_covariance.topRightCorner<3, 3>() = cov.topRightCorner<3, 3>() * R.transpose();
  out.pose_covariance.bottomLeftCorner<3, 3>() = R * cov.bottomLeftCorner<3, 3>();
  out.pose_covariance.bottomRightCorner<3, 3>() = R * cov.bottomRightCorner<3, 3>() * R.transpose();
  const double sg = config_.noise.gyro_noise_density;
  out.twist_covariance.setZero();
  out.twist_covariance.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * 0.01;  // ~0.1 m/s
  // Rate noise over a 200 Hz sample.
  out.twist_covariance.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * sg * sg * 200.0;
  out.mode = mode_;
  out.optimised = optimised;
  out.anchor = optimised;
  out.gyro_bias_radps = s.bias.gyro_radps;
  out.accel_bias_mps2 = s.bias.accel_mps2;
  if (window_.gravity_tilt_free()) out.gravity_map_mps2 = window_.gravity_map();
  out.sequence = 0;
  return out;
}

void LioEstimator::add_imu(const ImuSample& sample, std::vector<NavState>& states) {
  const ImuPushResult pushed = imu_.push(sample);
  if (pushed != ImuPushResult::kAccepted && pushed != ImuPushResult::kAcceptedOverwrote) return;
  if (!aligned_) {
    if (!first_imu_) first_imu_ = sample.stamp;
    std::optional<imu::StaticAlignmentResult> r = alignment_.add(sample);
    const std::optional<imu::StaticAlignmentResult> moving = moving_alignment_.add(sample);
    if (!r && moving && sample.stamp - *first_imu_ >= config_.moving_alignment_after) {
      r = moving;
      aligned_moving_ = true;
    }
    if (r) {
      aligned_ = r;
      imu::ImuState start;
      start.stamp = r->stamp;
      start.q_map_imu = r->q_map_imu;
      start.bias.gyro_radps = r->gyro_bias_radps;
      anchor_ = start;
      anchor_cov_.setZero();
      anchor_cov_.block<2, 2>(3, 3) =
          Eigen::Matrix2d::Identity() * r->tilt_sigma_rad * r->tilt_sigma_rad;
      anchor_cov_(5, 5) = 1e-6;
      propagated_ = start;
      propagated_last_ = sample;
      mode_ = EstimatorMode::kLidarInertial;
    }
    return;
  }
  // Odometry: one midpoint step from the previous sample with the anchor's biases.
  if (propagated_last_ && sample.stamp > propagated_last_->stamp) {
    imu::Preintegration step(imu::ImuNoise{}, propagated_.bias, propagated_last_->stamp);
    step.add(*propagated_last_);
    step.add(sample);
    const HostTime stamp = sample.stamp;
    propagated_ = step.predict(propagated_, window_.gravity_map());
    propagated_.stamp = stamp;
    propagated_last_ = sample;
    // Uncertainty grows from the anchor's with the IMU's white noise (random-walk model).
    Eigen::Matrix<double, 6, 6> cov = anchor_cov_;
    const double dt = (stamp - anchor_->stamp).seconds();
    const imu::ImuNoise& n =
        sample.from_backup_imu && config_.backup_noise ? *config_.backup_noise : config_.noise;
    const double sa = n.accel_noise_density, sg = n.gyro_noise_density;
    cov.topLeftCorner<3, 3>().diagonal().array() += sa * sa * dt * dt * dt / 3.0;
    cov.bottomRightCorner<3, 3>().diagonal().array() += sg * sg * dt;
    NavState s = to_nav_state(
        propagated_, sample.angular_velocity_radps - propagated_.bias.gyro_radps, false, cov);
    s.sequence = ++sequence_;
    // The first state after the alignment is where odometry kept apart from the back end starts.
    s.anchor = !first_state_emitted_;
    first_state_emitted_ = true;
    states.push_back(s);
  }
  release_scans(states);
}

void LioEstimator::add_scan(LidarScan scan, std::vector<NavState>& states) {
  if (!aligned_ || scan.end_stamp <= aligned_->stamp) {
    ++figures_.scans_skipped;  // the map starts once the IMU has aligned; this scan is before
    return;
  }
  gate_.push(std::move(scan));
  release_scans(states);
}

void LioEstimator::release_scans(std::vector<NavState>& states) {
  while (auto bundle = gate_.pop_ready(imu_, bundle_imu_)) process_scan(*bundle, states);
  // IMU older than what the window and the waiting scans need is no longer useful.
  HostTime keep_from = anchor_ ? anchor_->stamp : imu_.newest_stamp();
  if (const auto oldest = gate_.oldest_needed()) keep_from = std::min(keep_from, *oldest);
  if (!imu_.empty()) imu_.discard_before(keep_from - Duration::from_ms(50));
}

LioEstimator::Integrated LioEstimator::integrate(const imu::ImuState& from, HostTime t,
                                                 lidar::ScanMotion* motion) {
  Integrated out{imu::Preintegration(config_.noise, config_.backup_noise.value_or(config_.noise),
                                     from.bias, from.stamp),
                 false};
  imu_.samples_between(from.stamp, t, scratch_);
  if (scratch_.size() < 2) return out;
  if (motion != nullptr) motion->clear();
  std::vector<std::pair<HostTime, Eigen::Isometry3d>> lidar_poses;
  const auto record = [&] {
    if (motion == nullptr) return;
    const imu::ImuState s = out.pre.predict(from, window_.gravity_map());
    lidar_poses.emplace_back(out.pre.end(), imu::T_map_imu(s) * config_.T_imu_lidar);
  };
  // Start exactly at `from`: interpolate between the bracket below it and the next sample.
  std::size_t i = 0;
  if (scratch_[0].stamp < from.stamp) {
    out.pre.add(imu::interpolate_sample(scratch_[0], scratch_[1], from.stamp));
    i = 1;
  } else {
    out.pre.add(scratch_[0]);
    i = 1;
  }
  const bool starts_covered = scratch_[0].stamp <= from.stamp;
  record();
  for (; i < scratch_.size(); ++i) {
    if (scratch_[i].stamp >= t) {
      out.pre.add_until(t, scratch_[i]);
      record();
      out.covered = starts_covered;
      break;
    }
    out.pre.add(scratch_[i]);
    record();
  }
  if (motion != nullptr && !lidar_poses.empty()) {
    const Eigen::Isometry3d T_end_inv = lidar_poses.back().second.inverse();
    for (const auto& [stamp, T] : lidar_poses) {
      motion->stamps.push_back(stamp);
      motion->T_end_t.push_back(T_end_inv * T);
    }
  }
  return out;
}

void LioEstimator::reanchor_propagation(const imu::ImuState& state) {
  anchor_ = state;
  propagated_ = state;
  propagated_last_.reset();
  // Re-propagate through the samples already past the anchor (they were published from the old
  // anchor; the next ones continue from the corrected state).
  imu_.samples_between(state.stamp, imu_.newest_stamp(), scratch_);
  if (scratch_.size() < 2) return;
  std::optional<ImuSample> previous;
  for (std::size_t i = 0; i < scratch_.size(); ++i) {
    const ImuSample& s = scratch_[i];
    if (!previous) {
      previous = s.stamp < state.stamp && i + 1 < scratch_.size()
                     ? imu::interpolate_sample(s, scratch_[i + 1], state.stamp)
                     : s;
      continue;
    }
    if (s.stamp <= previous->stamp) continue;
    imu::Preintegration step(imu::ImuNoise{}, propagated_.bias, previous->stamp);
    step.add(*previous);
    step.add(s);
    propagated_ = step.predict(propagated_, window_.gravity_map());
    propagated_.stamp = s.stamp;
    previous = s;
  }
  propagated_last_ = previous;
}

const char* LioEstimator::divergence(const imu::ImuState& s) const {
  if (!s.p_map_imu_m.allFinite() || !s.q_map_imu.coeffs().allFinite()) {
    return "the state is not finite";
  }
  if (s.v_map_mps.norm() > config_.max_speed_mps) return "speed beyond estimator.max_speed_mps";
  if (s.bias.gyro_radps.norm() > config_.max_gyro_bias_radps) {
    return "gyro bias beyond estimator.max_gyro_bias_radps";
  }
  if (s.bias.accel_mps2.norm() > config_.max_accel_bias_mps2) {
    return "accelerometer bias beyond estimator.max_accel_bias_mps2";
  }
  return nullptr;
}

void LioEstimator::reinitialise(const imu::ImuState& at, const Eigen::Vector3d& v_map_mps,
                                const char* reason) {
  ++figures_.reinitialisations;
  figures_.last_reinitialisation_reason = reason;
  figures_.last_reinitialisation_stamp = at.stamp;
  mode_ = EstimatorMode::kReinitialising;
  imu::ImuState s = at;
  s.v_map_mps = v_map_mps;
  // Biases back to what the start-up alignment found: the window's may be what diverged.
  s.bias.gyro_radps = aligned_ ? aligned_->gyro_bias_radps : Eigen::Vector3d::Zero();
  s.bias.accel_mps2.setZero();
  strong_since_.reset();  // the speed and biases are to be found again
  Eigen::Matrix<double, 15, 1> sigma;
  sigma << Eigen::Vector3d::Constant(0.05), Eigen::Vector3d::Constant(0.02),
      Eigen::Vector3d::Constant(1.0), Eigen::Vector3d::Constant(0.02),
      Eigen::Vector3d::Constant(0.3);
  window_.reset(s, sigma);
}

bool LioEstimator::plausible(const lidar::ScanMatchResult& match,
                             const Eigen::Isometry3d& T_predicted) const {
  if (!match.ok) return false;
  const double jump_m = (match.T_map_lidar.translation() - T_predicted.translation()).norm();
  const double jump_rad =
      so3::log(Eigen::Matrix3d(T_predicted.linear().transpose() * match.T_map_lidar.linear()))
          .norm();
  return jump_m <= config_.max_match_jump_m && jump_rad <= config_.max_match_jump_rad;
}

std::optional<LioEstimator::LidarPrediction> LioEstimator::constant_velocity(HostTime t) const {
  if (!matched_[0] || !matched_[1] || matched_[1]->first <= matched_[0]->first ||
      t <= matched_[1]->first) {
    return std::nullopt;
  }
  const auto& [t0, T0] = *matched_[0];
  const auto& [t1, T1] = *matched_[1];
  const double dt01 = (t1 - t0).seconds();
  if (dt01 > 1.0) return std::nullopt;  // too old to extrapolate
  // The body twist between the last two matches, held.
  const Eigen::Isometry3d delta = T0.inverse() * T1;
  const Eigen::Vector3d w = so3::log(Eigen::Matrix3d(delta.linear())) / dt01;
  const Eigen::Vector3d v = delta.translation() / dt01;
  const auto at = [&](HostTime s) {
    const double dt = (s - t1).seconds();
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.linear() = so3::exp(w * dt);
    step.translation() = v * dt;
    return T1 * step;
  };
  LidarPrediction p;
  p.T_map_lidar = at(t);
  p.v_map_mps = T1.linear() * v;
  const Eigen::Isometry3d T_end_inv = p.T_map_lidar.inverse();
  for (HostTime s = t1; s < t; s += Duration::from_ms(10)) {
    p.motion.stamps.push_back(s);
    p.motion.T_end_t.push_back(T_end_inv * at(s));
  }
  p.motion.stamps.push_back(t);
  p.motion.T_end_t.push_back(Eigen::Isometry3d::Identity());
  return p;
}

Eigen::Vector3d LioEstimator::lidar_velocity_or_zero(HostTime t) const {
  const auto cv = constant_velocity(t);
  return cv ? cv->v_map_mps : Eigen::Vector3d::Zero();
}

imu::ImuState LioEstimator::imu_state_at(const Eigen::Isometry3d& T_map_lidar, HostTime t) const {
  const Eigen::Isometry3d T_imu = T_map_lidar * config_.T_imu_lidar.inverse();
  imu::ImuState s;
  s.stamp = t;
  s.p_map_imu_m = T_imu.translation();
  s.q_map_imu = Eigen::Quaterniond(T_imu.linear()).normalized();
  return s;
}

void LioEstimator::process_scan(const Bundle<LidarScan>& bundle, std::vector<NavState>& states) {
  const LidarScan& scan = bundle.measurement;
  const HostTime t = scan.end_stamp;
  if (bundle.kind == ReleaseKind::kDrained || !anchor_ || t <= anchor_->stamp) {
    ++figures_.scans_skipped;  // no IMU up to its end, or older than the state already estimated
    return;
  }
  const imu::ImuState from = window_.empty() ? *anchor_ : window_.latest();
  begin(LioStep::kPredict);
  Integrated integrated = integrate(from, t, &motion_);
  end(LioStep::kPredict);
  if (!integrated.covered || integrated.pre.empty()) {
    ++figures_.scans_skipped;
    return;
  }
  imu::ImuState predicted = integrated.pre.predict(from, window_.gravity_map());
  predicted.stamp = t;
  const Eigen::Isometry3d T_pred = imu::T_map_imu(predicted) * config_.T_imu_lidar;

  const auto points = scan.points.as<LidarPoint>();
  const std::span<const LidarPoint> point_span(points.data(), scan.point_count);
  begin(LioStep::kDeskew);
  lidar_.deskew(point_span, scan.start_stamp, motion_);
  end(LioStep::kDeskew);
  begin(LioStep::kFeatures);
  lidar_.extract_features();
  end(LioStep::kFeatures);
  const bool aided = aiding_ != nullptr && aiding_->active();
  if (aided != aided_degeneracy_) {
    aided_degeneracy_ = aided;
    const lidar::ScanMatcherConfig& m = config_.lidar.matcher;
    lidar_.set_translation_degeneracy(
        aided ? config_.aided_degeneracy_translation_threshold : m.degeneracy_translation_threshold,
        aided ? config_.aided_degenerate_information_scale : m.degenerate_information_scale);
  }
  begin(LioStep::kMatch);
  lidar::ScanMatchResult match = lidar_.match(T_pred);
  end(LioStep::kMatch);
  figures_.degenerate_directions = match.degenerate_directions;

  // A match far from the prediction is more likely a wrong basin than the truth. When it is the
  // IMU's prediction that led nowhere (a faulty or saturated IMU), the lidar alone may still
  // know: retry from its constant-velocity prediction, deskewed with that motion, and judge what
  // the retry says (match_retry.hpp).
  bool imu_suspect = false;
  std::optional<Eigen::Vector3d> lidar_velocity;
  if (!window_.empty() && !plausible(match, T_pred)) {
    match.ok = false;
    if (const auto cv = constant_velocity(t)) {
      lidar_.deskew(point_span, scan.start_stamp, cv->motion);
      lidar_.extract_features();
      lidar::ScanMatchResult retry = lidar_.match(cv->T_map_lidar);
      const MatchRetryVerdict verdict = judge_match_retry(
          plausible(retry, cv->T_map_lidar), plausible(retry, T_pred), retry.degenerate_directions);
      if (verdict != MatchRetryVerdict::kReject) match = retry;
      if (verdict == MatchRetryVerdict::kImuSuspect) {
        imu_suspect = true;
        lidar_velocity = cv->v_map_mps;
      }
    }
  }
  if (!match.ok) ++figures_.scans_rejected;
  if (match.ok && match.degenerate_directions > 0) {
    ++figures_.scans_degenerate;
    last_degenerate_stamp_ = t;
  }
  // A weakly pinned direction is only suspect where the lidar has recently shown it is in a
  // place it cannot pin (a roadway, a corridor): on an open street a scan's weakest direction
  // is right, and the cameras' motion, scaled by depths with their own errors, is not better.
  lidar_suspect_ = last_degenerate_stamp_ &&
                   (t - *last_degenerate_stamp_).seconds() <= config_.aided_suspect_window_s;
  if (!strong_since_ || !match.ok || match.degenerate_directions > 0) strong_since_ = t;
  lidar_settled_ =
      !lidar_suspect_ && (t - *strong_since_).seconds() >= config_.aided_settled_after_s;

  begin(LioStep::kWindow);
  // The map's tilt and an accelerometer bias only come apart in a turn where the lidar pins the
  // position: a turn along a corridor's axis or on an open stretch does not count.
  window_.set_position_pinned(match.ok && match.degenerate_directions == 0);
  if (window_.empty()) {
    // The first scan defines the map at the aligned IMU pose. Position and yaw are the map's
    // definition; tilt, velocity and gyro bias are as certain as the alignment made them.
    Eigen::Matrix<double, 15, 1> sigma;
    const double tilt = std::max(aligned_->tilt_sigma_rad, 1e-3);
    sigma << Eigen::Vector3d::Constant(1e-3), tilt, tilt, 1e-4,
        Eigen::Vector3d::Constant(aligned_moving_ ? 5.0 : 0.05),
        Eigen::Vector3d::Constant(aligned_moving_ ? 0.02 : 0.01), Eigen::Vector3d::Constant(0.2);
    window_.reset(predicted, sigma);
  } else if (imu_suspect) {
    // The IMU contradicts the lidar: its preintegration cannot join the window.
    reinitialise(imu_state_at(match.T_map_lidar, t), *lidar_velocity,
                 "the scan matched from the lidar's own motion pins every direction and is far "
                 "from the IMU's prediction: the IMU is distrusted");
  } else {
    add_to_window(predicted, integrated.pre, match);
  }
  imu::ImuState estimate = window_.latest();
  if (!imu_suspect) {
    mode_ = match.ok && match.degenerate_directions > 0 ? EstimatorMode::kDegenerate
                                                        : EstimatorMode::kLidarInertial;
  }
  if (const char* why = divergence(estimate)) {
    // Restart from the lidar's pose: this scan's when it matched, else where the lidar's own
    // motion says; only without either from where the IMU says.
    if (match.ok) {
      reinitialise(imu_state_at(match.T_map_lidar, t), lidar_velocity_or_zero(t), why);
    } else if (const auto cv = constant_velocity(t)) {
      reinitialise(imu_state_at(cv->T_map_lidar, t), cv->v_map_mps, why);
    } else {
      reinitialise(predicted, Eigen::Vector3d::Zero(), why);
    }
    estimate = window_.latest();
  }
  end(LioStep::kWindow);
  begin(LioStep::kMapUpdate);
  if (match.ok) {
    ++figures_.scans_used;
    const Eigen::Isometry3d T_map_lidar = imu::T_map_imu(estimate) * config_.T_imu_lidar;
    matched_[0] = matched_[1];
    matched_[1] = {t, T_map_lidar};
    matched_start_ = scan.start_stamp;
    ++matched_scans_;
    if (lidar_.commit(T_map_lidar) && config_.keep_map) {
      map_cloud_.add(lidar_.deskewed(), T_map_lidar);
      map_keyframes_.push_back({t, imu::T_map_imu(estimate)});
    }
  }
  anchor_cov_ = window_.size() > 1 ? window_.latest_pose_covariance()
                                   : Eigen::Matrix<double, 6, 6>::Identity() * 1e-6;
  reanchor_propagation(estimate);
  end(LioStep::kMapUpdate);

  const ImuSample& last = bundle_imu_.empty() ? ImuSample{} : bundle_imu_.back();
  NavState s = to_nav_state(estimate, last.angular_velocity_radps - estimate.bias.gyro_radps, true,
                            anchor_cov_);
  s.sequence = ++sequence_;
  states.push_back(s);
}

Eigen::Vector3d LioEstimator::body_rate(const imu::ImuState& state) const {
  if (bundle_imu_.empty()) return Eigen::Vector3d::Zero();
  return bundle_imu_.back().angular_velocity_radps - state.bias.gyro_radps;
}

bool LioEstimator::vehicle_motion_applies(const imu::ImuState& state) const {
  switch (config_.vehicle_motion) {
    case LioConfig::VehicleMotion::kOff:
      return false;
    case LioConfig::VehicleMotion::kEveryState:
      return true;
    case LioConfig::VehicleMotion::kWhereBlind:
      break;
  }
  if (!lidar_suspect_ || !motions_.empty()) return false;
  // The turn rate about the map's vertical, in the body.
  const Eigen::Vector3d up_base =
      state.q_map_imu.normalized().conjugate() * Eigen::Vector3d::UnitZ();
  return std::abs(body_rate(state).dot(up_base)) >= config_.vehicle_min_yaw_rate_radps;
}

void LioEstimator::add_to_window(const imu::ImuState& predicted, const imu::Preintegration& pre,
                                 const lidar::ScanMatchResult& match) {
  std::uint8_t modalities = kModalityImu;
  std::optional<LidarPose> lidar_factor;
  if (match.ok) {
    lidar_factor = LidarPose{match.T_map_lidar_measured, match.information};
    modalities |= kModalityLidar;
  }
  motions_.clear();
  if (aiding_ != nullptr) {
    aiding_->set_lidar_state({.weak = lidar_suspect_, .settled = lidar_settled_});
    aiding_->relative_motions(window_, predicted, motions_);
  }
  if (lidar_factor && lidar_suspect_) {
    if (!motions_.empty()) {
      reconcile(*lidar_factor);
    } else if (aiding_ != nullptr) {
      leave_weak_directions_to_imu(*lidar_factor);
    }
  }
  const imu::ImuState initial = initial_value(predicted, pre, match);
  // The states the motions start from, by id: adding a state may marginalise the oldest.
  from_ids_.clear();
  for (const RelativeMotion& m : motions_) from_ids_.push_back(window_.id(m.from_index));
  window_.add(initial, pre, lidar_factor);
  if (vehicle_motion_applies(initial)) {
    window_.add_factor(
        FactorKind::kVehicleMotion,
        std::make_unique<VehicleMotionFactor>(body_rate(initial), config_.vehicle_centre_m,
                                              config_.vehicle_lateral_sigma_mps,
                                              config_.vehicle_vertical_sigma_mps),
        {{window_.latest_id(), BlockRole::kPose}, {window_.latest_id(), BlockRole::kSpeedBias}});
    ++figures_.vehicle_motion_states;
  }
  for (std::size_t k = 0; k < motions_.size(); ++k) {
    const RelativeMotion& m = motions_[k];
    std::unique_ptr<ceres::LossFunction> loss;
    if (m.huber_sigma > 0) loss = std::make_unique<ceres::HuberLoss>(m.huber_sigma);
    const bool added = window_.add_factor(
        m.kind, std::make_unique<RelativePoseFactor>(m.T_k_j, m.information),
        {{from_ids_[k], BlockRole::kPose}, {window_.latest_id(), BlockRole::kPose}},
        std::move(loss));
    if (!added) continue;
    modalities |= m.kind == FactorKind::kVisible   ? kModalityVisible
                  : m.kind == FactorKind::kThermal ? kModalityThermal
                                                   : kModalityFused;
  }
  if (aiding_ != nullptr) modalities |= aiding_->add_factors(window_);
  window_.solve();
  if (aiding_ != nullptr) aiding_->after_solve(window_);
  figures_.modalities = modalities;
}

void LioEstimator::reconcile(LidarPose& lidar) {
  const imu::ImuState previous = window_.latest();
  const Eigen::Matrix3d R_i = previous.q_map_imu.toRotationMatrix();
  // The lidar's position of the new state relative to the previous one, in the previous frame.
  const Eigen::Isometry3d T_map_imu = lidar.T_map_lidar * config_.T_imu_lidar.inverse();
  const Eigen::Vector3d p_lidar =
      R_i.transpose() * (T_map_imu.translation() - previous.p_map_imu_m);
  // The cameras' combined translation and information in the same frame.
  Eigen::Matrix3d I_cam = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b_cam = Eigen::Vector3d::Zero();
  for (const RelativeMotion& m : motions_) {
    const Eigen::Matrix3d I = covariance_of(m.information).bottomRightCorner<3, 3>().inverse();
    // The factor's translation residual is in the measured frame: R_meas I R_measᵀ in frame i.
    const Eigen::Matrix3d R_m = m.T_i_j.linear();
    I_cam += R_m * I * R_m.transpose();
    b_cam += R_m * I * R_m.transpose() * m.T_i_j.translation();
  }
  const Eigen::Vector3d p_cam = (I_cam + 1e-9 * Eigen::Matrix3d::Identity()).ldlt().solve(b_cam);
  // The lidar's translation information in frame i (right perturbation: lidar axes at j).
  const Eigen::Matrix3d R_map_lidar = lidar.T_map_lidar.linear();
  const Eigen::Matrix3d R_i_lidar = R_i.transpose() * R_map_lidar;
  const Eigen::Matrix3d I_lidar_body = lidar.information.bottomRightCorner<3, 3>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(
      0.5 * (I_lidar_body + I_lidar_body.transpose()));
  std::array<Eigen::Vector3d, 3> overruled;
  std::size_t count = 0;
  for (int k = 0; k < 3; ++k) {
    const double lambda = es.eigenvalues()(k);
    if (lambda >= config_.aided_trusted_information) continue;  // the scan pins it firmly
    const Eigen::Vector3d e_lidar = es.eigenvectors().col(k);
    const Eigen::Vector3d e_i = R_i_lidar * e_lidar;
    const double I_c = e_i.dot(I_cam * e_i);
    if (I_c <= 0) continue;  // the cameras say nothing along it
    const double difference = e_i.dot(p_lidar - p_cam);
    const double variance = (lambda > 0 ? 1.0 / lambda : 1e9) + 1.0 / I_c;
    if (difference * difference <=
        config_.aided_consistency_sigma * config_.aided_consistency_sigma * variance) {
      continue;
    }
    // The scan and the cameras disagree along a direction the scan pins only weakly: an
    // aliased match (a roadway's uniform pipes) more often than a camera error, since the
    // cameras' motion passed its own checks. The scan says nothing there.
    overruled[count++] = e_lidar;
    ++figures_.lidar_directions_overruled;
  }
  drop_translations(lidar, std::span<const Eigen::Vector3d>(overruled.data(), count));
}

void LioEstimator::leave_weak_directions_to_imu(LidarPose& lidar) {
  if (config_.aided_blind_weak_ratio <= 0) return;
  const Eigen::Matrix3d I_t = lidar.information.bottomRightCorner<3, 3>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(0.5 * (I_t + I_t.transpose()));
  // Ascending: only a tube's signature, one weak translation under two firm ones. Elsewhere
  // (a corridor's end wall in a U-turn, with the camera's gate closed for a few frames) the IMU
  // alone would carry two directions through a fast turn: corridor seed 34 ran away 69 m so.
  const Eigen::Vector3d lambda = es.eigenvalues();
  const double firm = config_.aided_blind_weak_ratio * lambda(2);
  if (lambda(0) >= firm || lambda(1) < firm) return;
  const Eigen::Vector3d weakest = es.eigenvectors().col(0);
  drop_translations(lidar, std::span<const Eigen::Vector3d>(&weakest, 1));
  ++figures_.lidar_directions_left_to_imu;
}

imu::ImuState LioEstimator::initial_value(const imu::ImuState& predicted,
                                          const imu::Preintegration& pre,
                                          const lidar::ScanMatchResult& match) {
  if (!config_.pose_selection) return predicted;
  const imu::ImuState previous = window_.latest();
  const Eigen::Matrix3d R_prev = previous.q_map_imu.toRotationMatrix();
  // Each odometry's position with its information in the map frame (translation blocks of the
  // right-perturbation informations, rotated into the map).
  const auto in_map = [](const Eigen::Matrix3d& R, const Eigen::Matrix3d& information_body) {
    return Eigen::Matrix3d(R * information_body * R.transpose());
  };
  std::vector<WeightedPosition> cameras;
  std::optional<Eigen::Matrix3d> R_cio;
  for (const RelativeMotion& m : motions_) {
    const Eigen::Isometry3d T = imu::T_map_imu(previous) * m.T_i_j;
    const Eigen::Matrix3d cov_t = covariance_of(m.information).bottomRightCorner<3, 3>();
    cameras.push_back({T.translation(), in_map(T.linear(), cov_t.inverse())});
    if (!R_cio) R_cio = T.linear();
  }
  std::optional<Eigen::Isometry3d> T_lio;
  WeightedPosition lio;
  if (match.ok) {
    T_lio = match.T_map_lidar * config_.T_imu_lidar.inverse();
    lio.p = T_lio->translation();
    const Eigen::Matrix3d cov_t = covariance_of(match.information).bottomRightCorner<3, 3>();
    lio.information = in_map(match.T_map_lidar.linear(), cov_t.inverse());
  }
  PoseSelectionInput in;
  in.threshold_m = 0.5 * (previous.v_map_mps.norm() + predicted.v_map_mps.norm()) * pre.dt_s();
  in.imu = predicted.p_map_imu_m - previous.p_map_imu_m;
  std::optional<Eigen::Vector3d> p_cio, p_lci;
  if (T_lio) in.lio = lio.p - previous.p_map_imu_m;
  if (!cameras.empty()) {
    p_cio = combine(cameras.data(), cameras.size());
    if (p_cio) in.cio = *p_cio - previous.p_map_imu_m;
  }
  if (T_lio && p_cio) {
    std::vector<WeightedPosition> all = cameras;
    all.push_back(lio);
    // The IMU's prediction, as certain as the preintegration's position block says.
    const Eigen::Matrix3d cov_imu =
        pre.covariance().bottomRightCorner<3, 3>() + 1e-6 * Eigen::Matrix3d::Identity();
    all.push_back({predicted.p_map_imu_m, in_map(R_prev, cov_imu.inverse())});
    p_lci = combine(all.data(), all.size());
    if (p_lci) in.lci = *p_lci - previous.p_map_imu_m;
  }
  PoseSelectionFigures& f = figures_.selection;
  f.last_threshold_m = in.threshold_m;
  imu::ImuState initial = predicted;
  switch (select_pose(in)) {
    case PoseChoice::kImu:
      ++f.imu_only;
      break;
    case PoseChoice::kLidarInertial:
      ++f.lidar_inertial;
      initial.p_map_imu_m = T_lio->translation();
      initial.q_map_imu = Eigen::Quaterniond(T_lio->linear()).normalized();
      break;
    case PoseChoice::kVisualInertial:
      ++f.visual_inertial;
      initial.p_map_imu_m = *p_cio;
      initial.q_map_imu = Eigen::Quaterniond(*R_cio).normalized();
      break;
    case PoseChoice::kLidarVisualInertial:
      ++f.lidar_visual_inertial;
      initial.p_map_imu_m = *p_lci;
      if (T_lio) initial.q_map_imu = Eigen::Quaterniond(T_lio->linear()).normalized();
      break;
  }
  return initial;
}

bool LioEstimator::latest_matched_scan(MatchedScan& out) const {
  if (matched_scans_ == 0 || !matched_[1]) return false;
  out.index = matched_scans_;
  out.stamp = matched_[1]->first;
  out.start_stamp = matched_start_;
  out.T_map_lidar = matched_[1]->second;
  out.points_lidar = lidar_.deskewed();
  return true;
}

void LioEstimator::local_map(std::vector<Eigen::Vector3f>& points_map_m) const {
  points_map_m.clear();
  lidar_.map_points(points_map_m);
}

void LioEstimator::export_map(MapExport& out) const {
  if (!config_.keep_map) return;
  map_cloud_.collect(out.points_map_m);
  out.voxel_m = map_cloud_.voxel_m();
  out.keyframes.insert(out.keyframes.end(), map_keyframes_.begin(), map_keyframes_.end());
}

}  // namespace posed::estimator
