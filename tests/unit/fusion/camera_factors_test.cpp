// The camera back end (core/fusion/camera_factors): from frames of features with lidar depth it
// hands the window the motion of base_link between two states, bridging the frames' stamps to
// the states', and gates a stream out while its images are poor and back when they recover.

#include "core/fusion/camera_factors.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <random>

#include "core/math/so3.hpp"

namespace posed::fusion {
namespace {

constexpr double kFactorsFocalPx = 600;

/// base_link moving along x at 1 m/s while yawing at 0.2 rad/s, from the origin at t = 0.
Eigen::Isometry3d truth(double t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3::exp(Eigen::Vector3d(0, 0, 0.2 * t));
  T.translation() = Eigen::Vector3d(t, 0.1 * t * t, 0.0);
  return T;
}

imu::ImuState state_at(double t) {
  const Eigen::Isometry3d T = truth(t);
  imu::ImuState s;
  s.stamp = HostTime::from_ns(static_cast<std::int64_t>(std::llround(t * 1e9)));
  s.p_map_imu_m = T.translation();
  s.q_map_imu = Eigen::Quaterniond(T.linear());
  s.v_map_mps = Eigen::Vector3d(1, 0.2 * t, 0);
  return s;
}

Eigen::Isometry3d T_imu_cam() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // camera z forward along base_link x
  T.translation() = Eigen::Vector3d(0.577, 0.0, 0.833);
  return T;
}

class FactorsWorld {
 public:
  FactorsWorld() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> x(3, 12), y(-3, 3), z(-0.8, 2.0);
    for (int i = 0; i < 300; ++i) points_.emplace_back(x(rng), y(rng), z(rng));
  }
  explicit FactorsWorld(std::vector<Eigen::Vector3d> points) : points_(std::move(points)) {}
  /// The frame the camera sees at t: every point in front of it, with its depth.
  vision::FrontendFrame frame(double t, double confidence) const {
    vision::FrontendFrame f;
    f.stamp = HostTime::from_ns(static_cast<std::int64_t>(std::llround(t * 1e9)));
    f.mode = vision::FrontendMode::kVisible;
    const Eigen::Isometry3d T_cam_map = (truth(t) * T_imu_cam()).inverse();
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const Eigen::Vector3d p = T_cam_map * points_[i];
      if (p.z() < 0.5 || std::abs(p.x() / p.z()) > 0.5 || std::abs(p.y() / p.z()) > 0.4) continue;
      vision::FrontendFeature feature;
      feature.id = i;
      feature.normalised = p.hnormalized();
      feature.depth_m = p.z();
      feature.verified = true;
      feature.track_length = 10;
      f.features.push_back(feature);
    }
    f.quality.visible.valid = true;
    f.quality.visible.confidence = confidence;
    f.quality.visible.omega = 1.0 / confidence;
    f.quality.visible.gradient_metric = confidence;
    return f;
  }

 private:
  std::vector<Eigen::Vector3d> points_;
};

CameraFactorsConfig factors_config() {
  CameraFactorsConfig c;
  c.streams = {true, false, false};
  c.T_imu_sensor = {T_imu_cam(), T_imu_cam(), T_imu_cam()};
  c.focal_px = kFactorsFocalPx;
  return c;
}

/// A window with states at 0.0, 0.1, ... `t_last` s, on the truth.
void fill(estimator::SlidingWindow& w, double t_last) {
  Eigen::Matrix<double, 15, 1> sigma = Eigen::Matrix<double, 15, 1>::Constant(0.01);
  w.reset(state_at(0.0), sigma);
  imu::Preintegration pre(imu::ImuNoise{1e-3, 1e-2, 1e-5, 1e-4}, imu::ImuBias{}, HostTime{});
  for (double t = 0.1; t <= t_last + 1e-9; t += 0.1) w.add(state_at(t), pre, std::nullopt);
}

/// factors_config() with a gate that closes under confidence 0.2 and reopens over 0.3.
CameraFactorsConfig gated_config() {
  CameraFactorsConfig c = factors_config();
  c.min_confidence = 0.2;
  c.rejoin_confidence = 0.3;
  return c;
}

/// The motions `factors` give a new state at `t_state` + 0.1 s, the window filled up to `t_state`.
std::vector<estimator::RelativeMotion> motions_after(CameraFactors& factors,
                                                     estimator::SlidingWindow& window,
                                                     double t_state) {
  std::vector<estimator::RelativeMotion> motions;
  fill(window, t_state);
  factors.relative_motions(window, state_at(t_state + 0.1), motions);
  return motions;
}

/// Visible frames at 15 Hz from 13 ms (none on a state's stamp) up to `frames_until_s`, a window
/// of states up to 0.3 s, and the motions `factors` give a new state at 0.4 s.
std::vector<estimator::RelativeMotion> one_motion(CameraFactors& factors, const FactorsWorld& world,
                                                  double frames_until_s) {
  for (double t = 0.013; t < frames_until_s; t += 1.0 / 15) {
    factors.add_frame(vision::FrontendMode::kVisible, world.frame(t, 0.9));
  }
  estimator::SlidingWindow window(estimator::SlidingWindowConfig{});
  fill(window, 0.3);
  std::vector<estimator::RelativeMotion> motions;
  factors.relative_motions(window, state_at(0.4), motions);
  return motions;
}

TEST(CameraFactors, MeasuresTheMotionBetweenStatesFromFramesOffTheirStamps) {
  const FactorsWorld world;
  CameraFactors factors(factors_config());
  // Frames at 15 Hz with a phase: none falls on a state's stamp.
  const std::vector<estimator::RelativeMotion> motions = one_motion(factors, world, 0.5);
  ASSERT_EQ(motions.size(), 1u);
  EXPECT_EQ(motions[0].kind, estimator::FactorKind::kVisible);
  const Eigen::Isometry3d expected = truth(0.3).inverse() * truth(0.4);
  EXPECT_LT((motions[0].T_i_j.translation() - expected.translation()).norm(), 2e-3);
  // Translation only: the rotation rows carry no information.
  EXPECT_LT((motions[0].information.topLeftCorner<3, 3>().norm()), 1e-9);
  EXPECT_GT((motions[0].information.bottomRightCorner<3, 3>().trace()), 1e3);
  EXPECT_EQ(factors.figures()[0].factors, 1u);
}

TEST(CameraFactors, MotionsStartFromAKeyframeForKeyframeStates) {
  const FactorsWorld world;
  CameraFactorsConfig config = factors_config();
  config.keyframe_states = 3;
  CameraFactors factors(config);
  for (double t = 0.013; t < 1.0; t += 1.0 / 15)
    factors.add_frame(vision::FrontendMode::kVisible, world.frame(t, 0.9));
  estimator::SlidingWindow window(estimator::SlidingWindowConfig{});
  fill(window, 0.3);
  imu::Preintegration pre(imu::ImuNoise{1e-3, 1e-2, 1e-5, 1e-4}, imu::ImuBias{}, HostTime{});
  // The state at 0.3 s anchors the next three (0.4, 0.5, 0.6 s); then 0.6 s starts a keyframe.
  const double next_s[] = {0.4, 0.5, 0.6, 0.7};
  const double from_s[] = {0.3, 0.3, 0.3, 0.6};
  for (int k = 0; k < 4; ++k) {
    std::vector<estimator::RelativeMotion> motions;
    factors.relative_motions(window, state_at(next_s[k]), motions);
    ASSERT_EQ(motions.size(), 1u) << next_s[k];
    const estimator::RelativeMotion& m = motions[0];
    EXPECT_NEAR(window.state(m.from_index).stamp.seconds(), from_s[k], 1e-6) << next_s[k];
    const Eigen::Isometry3d T_k_j = truth(from_s[k]).inverse() * truth(next_s[k]);
    const Eigen::Isometry3d T_i_j = truth(next_s[k] - 0.1).inverse() * truth(next_s[k]);
    EXPECT_LT((m.T_k_j.translation() - T_k_j.translation()).norm(), 2e-3) << next_s[k];
    EXPECT_LT((m.T_i_j.translation() - T_i_j.translation()).norm(), 2e-3) << next_s[k];
    window.add(state_at(next_s[k]), pre, std::nullopt);
  }
  EXPECT_EQ(factors.figures()[0].factors, 4u);
  EXPECT_EQ(factors.figures()[0].keyframe_factors, 2u);
  // The keyframe at 0.6 s would anchor 0.8 s too; where the lidar pins every direction the
  // motion starts from the previous state instead.
  factors.set_lidar_state({.weak = false});
  std::vector<estimator::RelativeMotion> motions;
  factors.relative_motions(window, state_at(0.8), motions);
  ASSERT_EQ(motions.size(), 1u);
  EXPECT_NEAR(window.state(motions[0].from_index).stamp.seconds(), 0.7, 1e-6);
  EXPECT_EQ(factors.figures()[0].keyframe_factors, 2u);
}

TEST(CameraFactors, APredictionTooSlowIsCorrectedOverTheFramesSpan) {
  // The window's prediction for the state at 0.4 s has the robot 30 % too slow since 0.3 s (a
  // degenerate corridor's drift). The frames measure the motion between their stamps; only the
  // bridge from the last frame (0.346 s) to the state comes from the prediction.
  const FactorsWorld world;
  CameraFactors factors(factors_config());
  for (double t = 0.013; t < 0.5; t += 1.0 / 15) {
    factors.add_frame(vision::FrontendMode::kVisible, world.frame(t, 0.9));
  }
  estimator::SlidingWindow window(estimator::SlidingWindowConfig{});
  fill(window, 0.3);
  imu::ImuState next = state_at(0.4);
  const Eigen::Vector3d p_03 = truth(0.3).translation();
  next.p_map_imu_m = p_03 + 0.7 * (next.p_map_imu_m - p_03);
  std::vector<estimator::RelativeMotion> motions;
  factors.relative_motions(window, next, motions);
  ASSERT_EQ(motions.size(), 1u);
  const Eigen::Isometry3d expected = truth(0.3).inverse() * truth(0.4);
  const Eigen::Vector3d predicted = truth(0.3).inverse() * next.p_map_imu_m;
  const double prediction_error = (predicted - expected.translation()).norm();
  const double error = (motions[0].T_i_j.translation() - expected.translation()).norm();
  // The bridge is 54 ms of the 100 ms: about that share of the prediction's error remains.
  EXPECT_LT(error, 0.6 * prediction_error);
  EXPECT_GT(error, 0.4 * prediction_error);
}

TEST(CameraFactors, WhereTheLidarIsWeakTheGateKeepsTheNearFeaturesAStaleSpeedMisplaces) {
  // A corridor's view: distant features, which agree with any speed, and near ones on the walls,
  // which a prediction that has the robot standing still since 0.3 s misplaces by a few pixels.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> far_x(20, 30), far_y(-4, 4), far_z(-0.5, 2.5);
  std::uniform_real_distribution<double> near_x(3, 4), near_y(0.8, 1.3), near_z(0, 1.6);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 60; ++i) points.emplace_back(far_x(rng), far_y(rng), far_z(rng));
  for (int i = 0; i < 30; ++i)
    points.emplace_back(near_x(rng) + 0.4 * i / 30.0, (i % 2 == 0 ? 1 : -1) * near_y(rng),
                        near_z(rng));
  const FactorsWorld world(points);
  const auto measure = [&](bool lidar_weak) {
    CameraFactors factors(factors_config());
    factors.set_lidar_state({.weak = lidar_weak});
    for (double t = 0.013; t < 0.5; t += 1.0 / 15)
      factors.add_frame(vision::FrontendMode::kVisible, world.frame(t, 0.9));
    estimator::SlidingWindow window(estimator::SlidingWindowConfig{});
    fill(window, 0.3);
    imu::ImuState next = state_at(0.4);
    next.p_map_imu_m = truth(0.3).translation();
    std::vector<estimator::RelativeMotion> motions;
    factors.relative_motions(window, next, motions);
    EXPECT_EQ(motions.size(), 1u);
    return factors.figures()[0].inliers;
  };
  // At 3 px (a lidar that pins everything) the near features are left out; at 6 px (the lidar
  // recently degenerate) they stay in the pair's motion (132 against 176 observations).
  const int strong = measure(false);
  const int weak = measure(true);
  EXPECT_GT(weak, strong + 20);
}

TEST(CameraFactors, WhereTheLidarIsStrongAFactorSaysNoMoreThanItsTranslationFloor) {
  // Where the scans pin the motion to millimetres, a frame pair's errors would only add noise:
  // its translation carries at least strong_lidar_floor_translation_m of sigma (30 mm here) once
  // the lidar has settled, where the lidar is weak or not yet settled only floor_translation_m
  // (2 mm).
  const FactorsWorld world;
  const auto translation_information = [&](bool lidar_weak, bool lidar_settled = true) {
    CameraFactorsConfig c = factors_config();
    c.strong_lidar_floor_translation_m = 0.03;
    CameraFactors factors(c);
    factors.set_lidar_state({.weak = lidar_weak, .settled = lidar_settled});
    const std::vector<estimator::RelativeMotion> motions = one_motion(factors, world, 0.45);
    EXPECT_EQ(motions.size(), 1u);
    if (motions.empty()) return 0.0;
    const Eigen::Matrix3d info = motions[0].information.bottomRightCorner<3, 3>();
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(info).eigenvalues().maxCoeff();
  };
  const double strong = translation_information(false);
  const double weak = translation_information(true);
  const double unsettled = translation_information(false, false);
  EXPECT_LE(strong, 1.0 / (0.03 * 0.03) * 1.0001);
  EXPECT_GT(strong, 0.5 / (0.03 * 0.03));  // the floor, not the features, bounds it
  EXPECT_GT(weak, 10 * strong);
  EXPECT_GT(unsettled, 10 * strong);
}

TEST(CameraFactors, AStreamIsGatedOutWhileItsImagesArePoorAndReturns) {
  const FactorsWorld world;
  CameraFactors factors(gated_config());
  estimator::SlidingWindow window(estimator::SlidingWindowConfig{});
  double t_frame = 0.013;
  const auto frames_until = [&](double t, double confidence) {
    for (; t_frame < t; t_frame += 1.0 / 15) {
      factors.add_frame(vision::FrontendMode::kVisible, world.frame(t_frame, confidence));
    }
  };
  const auto step = [&](double t_state) { return motions_after(factors, window, t_state).size(); };
  frames_until(0.45, 0.9);
  EXPECT_EQ(step(0.3), 1u);
  frames_until(0.85, 0.05);  // blinded: 6 poor frames
  EXPECT_FALSE(factors.figures()[0].active);
  EXPECT_EQ(step(0.7), 0u);
  EXPECT_EQ(factors.figures()[0].gated_out, 1u);
  frames_until(1.05, 0.25);  // better, but under the rejoin threshold
  EXPECT_FALSE(factors.figures()[0].active);
  frames_until(1.55, 0.9);  // recovered
  EXPECT_TRUE(factors.figures()[0].active);
  EXPECT_EQ(step(1.4), 1u);
  EXPECT_EQ(factors.figures()[0].left, 1u);
  EXPECT_EQ(factors.figures()[0].rejoined, 1u);
}

TEST(CameraFactors, TheThermalStreamStandsByWhileTheVisibleOneSeesAndStandsInWhenItIsBlind) {
  const FactorsWorld world;
  const auto run = [&](bool standby) {
    CameraFactorsConfig c = gated_config();
    c.streams = {true, true, false};
    c.thermal_standby = standby;
    CameraFactors factors(c);
    estimator::SlidingWindow window(estimator::SlidingWindowConfig{});
    double t_frame = 0.013;
    const auto frames_until = [&](double t, double visible_confidence) {
      for (; t_frame < t; t_frame += 1.0 / 15) {
        factors.add_frame(vision::FrontendMode::kVisible, world.frame(t_frame, visible_confidence));
        vision::FrontendFrame thermal = world.frame(t_frame, 0.9);  // smoke does not blind it
        thermal.mode = vision::FrontendMode::kThermal;
        thermal.quality.thermal = thermal.quality.visible;
        factors.add_frame(vision::FrontendMode::kThermal, thermal);
      }
    };
    // The kinds of factor a new state after `t_state` gets.
    const auto kinds = [&](double t_state) {
      std::vector<estimator::FactorKind> out;
      for (const estimator::RelativeMotion& m : motions_after(factors, window, t_state)) {
        out.push_back(m.kind);
      }
      return out;
    };
    using K = estimator::FactorKind;
    std::vector<std::vector<K>> steps;
    frames_until(0.45, 0.9);
    steps.push_back(kinds(0.3));
    frames_until(0.85, 0.05);  // smoke: the visible stream's gate closes
    EXPECT_FALSE(factors.figures()[0].active);
    // On standby the thermal stream counts for the lidar once it has given a motion.
    EXPECT_EQ(factors.active(), !standby);
    steps.push_back(kinds(0.7));
    EXPECT_TRUE(factors.active());
    frames_until(1.55, 0.9);  // clear again
    EXPECT_TRUE(factors.figures()[0].active);
    steps.push_back(kinds(1.4));
    return std::make_pair(steps, factors.figures()[1]);
  };
  using K = estimator::FactorKind;
  const auto [standby, thermal] = run(true);
  EXPECT_EQ(standby, (std::vector<std::vector<K>>{{K::kVisible}, {K::kThermal}, {K::kVisible}}));
  EXPECT_EQ(thermal.standby, 2u);
  EXPECT_EQ(thermal.factors, 1u);
  EXPECT_TRUE(thermal.active);  // its own gate never closed

  const auto [equal, thermal_equal] = run(false);
  EXPECT_EQ(equal, (std::vector<std::vector<K>>{
                       {K::kVisible, K::kThermal}, {K::kThermal}, {K::kVisible, K::kThermal}}));
  EXPECT_EQ(thermal_equal.standby, 0u);
}

CameraFactorsConfig landmark_config() {
  CameraFactorsConfig c = factors_config();
  c.coupling = CameraCoupling::kLandmarks;
  return c;
}

/// Runs states every 0.1 s from 0 to `t_last` s on the truth, frames at 15 Hz off the states'
/// stamps; each frame reaches the back end `frame_delay_states` states after the state it falls
/// before. Returns the window's visible factors after the last state.
std::size_t run_landmarks(CameraFactors& factors, const FactorsWorld& world, double t_last,
                          int frame_delay_states, estimator::SlidingWindow& window) {
  Eigen::Matrix<double, 15, 1> sigma = Eigen::Matrix<double, 15, 1>::Constant(0.01);
  window.reset(state_at(0.0), sigma);
  imu::Preintegration pre(imu::ImuNoise{1e-3, 1e-2, 1e-5, 1e-4}, imu::ImuBias{}, HostTime{});
  double t_frame = 0.013;
  std::vector<estimator::RelativeMotion> motions;
  for (int k = 1; k * 0.1 <= t_last + 1e-9; ++k) {
    for (; t_frame < (k - frame_delay_states) * 0.1; t_frame += 1.0 / 15) {
      factors.add_frame(vision::FrontendMode::kVisible, world.frame(t_frame, 0.9));
    }
    motions.clear();
    factors.relative_motions(window, state_at(k * 0.1), motions);
    EXPECT_TRUE(motions.empty());  // landmarks replace the between factors
    window.add(state_at(k * 0.1), pre, std::nullopt);
    factors.add_factors(window);
  }
  return window.factor_counts()[static_cast<std::size_t>(estimator::FactorKind::kVisible)];
}

TEST(CameraFactors, LandmarksTieLaterStatesToWhereAFeatureWasFirstSeen) {
  const FactorsWorld world;
  CameraFactors factors(landmark_config());
  estimator::SlidingWindow window(estimator::SlidingWindowConfig{});
  const std::size_t in_window = run_landmarks(factors, world, 0.6, 0, window);
  const VisualLandmarksFigures& f = factors.landmarks(vision::FrontendMode::kVisible).figures();
  EXPECT_GT(f.anchored, 20u);
  EXPECT_GT(in_window, 100u);
  EXPECT_EQ(f.factors, in_window);  // nothing marginalised yet: 7 states
  EXPECT_EQ(f.still, 0u);
  EXPECT_EQ(f.gated, 0u);
  // On the truth every factor is explained to a fraction of a pixel (the bridges from the frames'
  // stamps to the states' are interpolated).
  std::vector<double> residuals;
  window.residual_norms(estimator::FactorKind::kVisible, residuals);
  ASSERT_EQ(residuals.size(), in_window);
  EXPECT_LT(*std::max_element(residuals.begin(), residuals.end()), 0.2);
  EXPECT_EQ(factors.figures()[0].factors, in_window);
}

TEST(CameraFactors, ALandmarkFrameThatArrivesAfterItsStateIsStillThatStatesObservation) {
  const FactorsWorld world;
  CameraFactors in_time(landmark_config()), late(landmark_config());
  estimator::SlidingWindow w_in_time(estimator::SlidingWindowConfig{}),
      w_late(estimator::SlidingWindowConfig{});
  const std::size_t n_in_time = run_landmarks(in_time, world, 0.8, 0, w_in_time);
  // A frame comes one state late: the newest state has none yet, the one before gets its own.
  const std::size_t n_late = run_landmarks(late, world, 0.9, 1, w_late);
  // Late by a state, the run one state longer holds the same observations up to 0.8 s.
  EXPECT_EQ(n_late, n_in_time);
  std::vector<double> residuals;
  w_late.residual_norms(estimator::FactorKind::kVisible, residuals);
  EXPECT_LT(*std::max_element(residuals.begin(), residuals.end()), 0.2);
}

TEST(CameraFactors, ALandmarkThatHoldsStillInTheImageIsDropped) {
  const FactorsWorld world;
  CameraFactors factors(landmark_config());
  estimator::SlidingWindow window(estimator::SlidingWindowConfig{});
  Eigen::Matrix<double, 15, 1> sigma = Eigen::Matrix<double, 15, 1>::Constant(0.01);
  window.reset(state_at(0.0), sigma);
  imu::Preintegration pre(imu::ImuNoise{1e-3, 1e-2, 1e-5, 1e-4}, imu::ImuBias{}, HostTime{});
  double t_frame = 0.013;
  for (int k = 1; k <= 8; ++k) {
    for (; t_frame < k * 0.1; t_frame += 1.0 / 15) {
      vision::FrontendFrame frame = world.frame(t_frame, 0.9);
      // A corner of the lamp's shading on the wall: 2 m away, always at the same pixel.
      vision::FrontendFeature still;
      still.id = 100000;
      still.normalised = Eigen::Vector2d(0.3, 0.1);
      still.depth_m = 2.0;
      still.verified = true;
      still.track_length = 10;
      frame.features.push_back(still);
      factors.add_frame(vision::FrontendMode::kVisible, frame);
    }
    window.add(state_at(k * 0.1), pre, std::nullopt);
    factors.add_factors(window);
  }
  const VisualLandmarksFigures& f = factors.landmarks(vision::FrontendMode::kVisible).figures();
  EXPECT_EQ(f.still, 1u);
  std::vector<double> residuals;
  window.residual_norms(estimator::FactorKind::kVisible, residuals);
  EXPECT_LT(*std::max_element(residuals.begin(), residuals.end()), 0.2);  // none of it entered
}

TEST(CameraFactors, LandmarksLeaveWithTheirStreamsQualityGate) {
  const FactorsWorld world;
  CameraFactors factors(landmark_config());
  estimator::SlidingWindow window(estimator::SlidingWindowConfig{});
  run_landmarks(factors, world, 0.4, 0, window);
  EXPECT_GT(factors.landmarks(vision::FrontendMode::kVisible).figures().tracked, 0u);
  imu::Preintegration pre(imu::ImuNoise{1e-3, 1e-2, 1e-5, 1e-4}, imu::ImuBias{}, HostTime{});
  for (double t = 0.413; t < 0.8; t += 1.0 / 15) {  // blinded
    factors.add_frame(vision::FrontendMode::kVisible, world.frame(t, 0.01));
  }
  ASSERT_FALSE(factors.figures()[0].active);
  const std::uint64_t before = factors.landmarks(vision::FrontendMode::kVisible).figures().factors;
  window.add(state_at(0.5), pre, std::nullopt);
  EXPECT_EQ(factors.add_factors(window), 0);
  EXPECT_EQ(factors.landmarks(vision::FrontendMode::kVisible).figures().factors, before);
  EXPECT_EQ(factors.landmarks(vision::FrontendMode::kVisible).tracked(), 0u);
}

}  // namespace
}  // namespace posed::fusion
