// posectl bench backend: what the cameras cost the back end on one core. A rig drives straight at
// 1 m/s past 400 points; 15 Hz frames see them with 0.5 px of noise and lidar depth, states come
// at 10 Hz with preintegrated IMU and lidar poses in a 10-state window (the LIO window's shape).
// Per state: the camera back end's frame-to-frame motion (CameraFactors::relative_motions, one
// stream) and the window solve with its camera factor, against the same solve without cameras;
// and the same with the stream's features as landmarks (estimator.camera_coupling: landmarks):
// their reprojection factors added (CameraFactors::add_factors) and the window solved.

#include <algorithm>
#include <chrono>
#include <random>
#include <vector>

#include "core/estimator/factors.hpp"
#include "core/estimator/sliding_window.hpp"
#include "core/fusion/camera_factors.hpp"
#include "tools/posectl/bench.hpp"

namespace posed::posectl {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kGravity = 9.805;
constexpr double kImuHz = 200;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

HostTime at(double t) {
  return HostTime::from_ns(static_cast<std::int64_t>(std::llround(t * 1e9)));
}

Eigen::Isometry3d T_imu_cam() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T.translation() = Eigen::Vector3d(0.577, 0.0, 0.833);
  return T;
}

/// base_link at t: straight along x at 1 m/s.
Eigen::Isometry3d truth(double t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(t, 0, 0);
  return T;
}

imu::ImuState state_at(double t) {
  imu::ImuState s;
  s.stamp = at(t);
  s.p_map_imu_m = truth(t).translation();
  s.v_map_mps = Eigen::Vector3d(1, 0, 0);
  return s;
}

struct Scene {
  std::vector<Eigen::Vector3d> points;
  std::mt19937 rng{3};
  Scene() {
    std::uniform_real_distribution<double> x(0, 200), y(-3, 3), z(-0.8, 2.0);
    for (int i = 0; i < 4000; ++i) points.emplace_back(x(rng), y(rng), z(rng));
  }
  vision::FrontendFrame frame(double t) {
    std::normal_distribution<double> noise(0, 0.5 / 617.0);
    vision::FrontendFrame f;
    f.stamp = at(t);
    f.mode = vision::FrontendMode::kVisible;
    const Eigen::Isometry3d T_cam_map = (truth(t) * T_imu_cam()).inverse();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d p = T_cam_map * points[i];
      if (p.z() < 1 || p.z() > 15 || std::abs(p.x() / p.z()) > 0.5 || std::abs(p.y() / p.z()) > 0.4)
        continue;
      vision::FrontendFeature feature;
      feature.id = i;
      feature.normalised = p.hnormalized() + Eigen::Vector2d(noise(rng), noise(rng));
      feature.depth_m = p.z();
      feature.verified = true;
      feature.track_length = 10;
      f.features.push_back(feature);
      if (f.features.size() >= 300) break;
    }
    f.quality.visible.valid = true;
    f.quality.visible.confidence = 0.7;
    f.quality.visible.gradient_metric = 0.3;
    f.quality.visible.omega = 1.4;
    return f;
  }
};

imu::Preintegration preintegrate(double t0, double t1) {
  imu::Preintegration pre(imu::ImuNoise{2.3e-3, 3.8e-2, 1.4e-5, 1.1e-3}, imu::ImuBias{}, at(t0));
  for (double t = t0; t <= t1 + 1e-9; t += 1.0 / kImuHz) {
    ImuSample s;
    s.stamp = at(t);
    s.specific_force_mps2 = Eigen::Vector3d(0, 0, kGravity);
    pre.add(s);
  }
  return pre;
}

}  // namespace

int bench_backend() {
  Scene scene;
  fusion::CameraFactorsConfig c;
  c.streams = {true, false, false};
  c.T_imu_sensor = {T_imu_cam(), T_imu_cam(), T_imu_cam()};
  c.focal_px = 617;
  fusion::CameraFactors factors(c);
  fusion::CameraFactorsConfig lc = c;
  lc.coupling = fusion::CameraCoupling::kLandmarks;
  fusion::CameraFactors landmark_factors(lc);
  estimator::SlidingWindowConfig wc;
  wc.size = 10;
  wc.gravity_mps2 = kGravity;
  estimator::SlidingWindow with(wc), without(wc), landmarks(wc);
  Eigen::Matrix<double, 15, 1> sigma = Eigen::Matrix<double, 15, 1>::Constant(0.01);
  with.reset(state_at(0), sigma);
  without.reset(state_at(0), sigma);
  landmarks.reset(state_at(0), sigma);
  estimator::LidarPose lidar;
  lidar.information.setIdentity();
  lidar.information.topLeftCorner<3, 3>() *= 1e6;
  lidar.information.bottomRightCorner<3, 3>() *= 1e4;
  std::vector<double> motion_ms, solve_with_ms, solve_without_ms, landmarks_ms;
  double landmark_factors_in_window = 0;
  std::vector<estimator::RelativeMotion> motions;
  double t_frame = 0.021;
  const int states = 600;
  for (int k = 1; k <= states; ++k) {
    const double t = 0.1 * k;
    for (; t_frame <= t; t_frame += 1.0 / 15) {
      const vision::FrontendFrame frame = scene.frame(t_frame);
      factors.add_frame(vision::FrontendMode::kVisible, frame);
      landmark_factors.add_frame(vision::FrontendMode::kVisible, frame);
    }
    const imu::Preintegration pre = preintegrate(t - 0.1, t);
    lidar.T_map_lidar = truth(t);
    motions.clear();
    auto t0 = Clock::now();
    factors.relative_motions(with, state_at(t), motions);
    motion_ms.push_back(ms_since(t0));
    std::vector<std::uint64_t> from_ids;
    for (const auto& m : motions) from_ids.push_back(with.id(m.from_index));
    with.add(state_at(t), pre, lidar);
    without.add(state_at(t), pre, lidar);
    for (std::size_t j = 0; j < motions.size(); ++j) {
      const auto& m = motions[j];
      with.add_factor(m.kind,
                      std::make_unique<estimator::RelativePoseFactor>(m.T_k_j, m.information),
                      {{from_ids[j], estimator::BlockRole::kPose},
                       {with.latest_id(), estimator::BlockRole::kPose}},
                      std::make_unique<ceres::HuberLoss>(m.huber_sigma));
    }
    t0 = Clock::now();
    with.solve();
    factors.after_solve(with);
    solve_with_ms.push_back(ms_since(t0));
    t0 = Clock::now();
    without.solve();
    solve_without_ms.push_back(ms_since(t0));
    motions.clear();
    landmark_factors.relative_motions(landmarks, state_at(t), motions);  // none: landmarks only
    landmarks.add(state_at(t), pre, lidar);
    t0 = Clock::now();
    landmark_factors.add_factors(landmarks);
    landmarks.solve();
    landmark_factors.after_solve(landmarks);
    landmarks_ms.push_back(ms_since(t0));
    landmark_factors_in_window += static_cast<double>(
        landmarks.factor_counts()[static_cast<std::size_t>(estimator::FactorKind::kVisible)]);
  }
  const double factors_added = static_cast<double>(factors.figures()[0].factors);
  report("backend", "states", states, "count");
  report("backend", "camera_factors", factors_added, "count");
  report("backend", "frame_motion_median", quantile(motion_ms, 0.5), "ms");
  report("backend", "frame_motion_p99", quantile(motion_ms, 0.99), "ms");
  report("backend", "solve_with_cameras_median", quantile(solve_with_ms, 0.5), "ms");
  report("backend", "solve_with_cameras_p99", quantile(solve_with_ms, 0.99), "ms");
  report("backend", "solve_without_cameras_median", quantile(solve_without_ms, 0.5), "ms");
  report("backend", "solve_without_cameras_p99", quantile(solve_without_ms, 0.99), "ms");
  std::vector<double> total(motion_ms.size());
  for (std::size_t i = 0; i < total.size(); ++i) {
    total[i] = motion_ms[i] + solve_with_ms[i] - solve_without_ms[i];
  }
  // A state consumes one camera frame pair; frames arrive at 15 Hz, states at 10 Hz.
  report(
      "backend", "iterations_with_cameras_mean",
      static_cast<double>(with.counters().iterations) / static_cast<double>(with.counters().solves),
      "count");
  report("backend", "iterations_without_cameras_mean",
         static_cast<double>(without.counters().iterations) /
             static_cast<double>(without.counters().solves),
         "count");
  report("backend", "cameras_per_state_median", quantile(total, 0.5), "ms");
  report("backend", "cameras_per_state_p99", quantile(total, 0.99), "ms");
  report("backend", "cameras_per_frame_median", quantile(total, 0.5) * 10.0 / 15.0, "ms");
  for (std::size_t i = 0; i < landmarks_ms.size(); ++i) landmarks_ms[i] -= solve_without_ms[i];
  report("backend", "landmark_factors_in_window_mean", landmark_factors_in_window / states,
         "count");
  report("backend", "landmarks_per_state_median", quantile(landmarks_ms, 0.5), "ms");
  report("backend", "landmarks_per_state_p99", quantile(landmarks_ms, 0.99), "ms");
  return factors_added > 0.9 * states ? 0 : 1;
}

}  // namespace posed::posectl
