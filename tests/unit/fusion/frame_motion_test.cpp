// The frame-to-frame camera motion from features with lidar depth (core/fusion/frame_motion): the
// true motion from a poor guess, outliers removed, a covariance that matches the spread of noisy
// estimates, and nothing from features that do not pin the motion.

#include "core/fusion/frame_motion.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/math/so3.hpp"

namespace posed::fusion {
namespace {

constexpr double kFocalPx = 600;

struct Frames {
  std::vector<FrameFeature> a, b;
};

/// `n` points 2-8 m ahead of camera a seen from a and from b = a * T_a_b, with pixel noise
/// `noise_px` and lidar depth on every `depth_every`-th feature in each frame.
Frames make_frames(const Eigen::Isometry3d& T_a_b, int n, double noise_px, std::mt19937& rng,
                   int depth_every = 1) {
  std::uniform_real_distribution<double> lateral(-0.5, 0.5), depth(2, 8);
  std::normal_distribution<double> noise(0, noise_px / kFocalPx);
  Frames f;
  for (int k = 0; k < n; ++k) {
    const double z = depth(rng);
    const Eigen::Vector3d X_a(lateral(rng) * z, 0.6 * lateral(rng) * z, z);
    const Eigen::Vector3d X_b = T_a_b.inverse() * X_a;
    const auto id = static_cast<std::uint64_t>(k);
    FrameFeature fa{id, X_a.hnormalized() + Eigen::Vector2d(noise(rng), noise(rng)), X_a.z()};
    FrameFeature fb{id, X_b.hnormalized() + Eigen::Vector2d(noise(rng), noise(rng)), X_b.z()};
    if (k % depth_every != 0) fa.depth_m = std::numeric_limits<double>::quiet_NaN();
    if ((k + 1) % depth_every != 0) fb.depth_m = std::numeric_limits<double>::quiet_NaN();
    f.a.push_back(fa);
    f.b.push_back(fb);
  }
  return f;
}

Eigen::Isometry3d forward_motion() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3::exp(Eigen::Vector3d(0.01, -0.02, 0.005));
  T.translation() = Eigen::Vector3d(0.02, -0.01, 0.12);  // mostly along the optical axis
  return T;
}

FrameMotionConfig config() {
  FrameMotionConfig c;
  c.pixel_sigma = 1.0 / kFocalPx;
  return c;
}

TEST(FrameMotion, FindsTheMotionFromIdentity) {
  std::mt19937 rng(3);
  const Eigen::Isometry3d T = forward_motion();
  const Frames f = make_frames(T, 150, 0.5, rng);
  const FrameMotion m = estimate_frame_motion(f.a, f.b, Eigen::Isometry3d::Identity(), config());
  ASSERT_TRUE(m.ok());
  EXPECT_LT((m.T_a_b.translation() - T.translation()).norm(), 0.003);
  EXPECT_LT(so3::log(Eigen::Matrix3d(T.linear().transpose() * m.T_a_b.linear())).norm(), 5e-4);
  EXPECT_EQ(m.observations, 300);                        // both directions
  EXPECT_NEAR(m.rms_sigma, 0.5 * std::sqrt(2.0), 0.25);  // two frames' noise in each residual
}

TEST(FrameMotion, DropsFeaturesWithAWrongDepth) {
  std::mt19937 rng(4);
  const Eigen::Isometry3d T = forward_motion();
  Frames f = make_frames(T, 150, 0.3, rng);
  // A fifth of frame a's depths belong to the wall behind: twice as far.
  for (std::size_t k = 0; k < f.a.size(); k += 5) f.a[k].depth_m *= 2.0;
  const FrameMotion m = estimate_frame_motion(f.a, f.b, Eigen::Isometry3d::Identity(), config());
  ASSERT_TRUE(m.ok());
  const double error_m = (m.T_a_b.translation() - T.translation()).norm();
  EXPECT_LT(error_m, 0.004);
  EXPECT_LT(m.inliers, m.observations);
  // Kept, the wrong depths pull the motion further off.
  FrameMotionConfig keep_all = config();
  keep_all.outlier_sigma = 1e6;
  keep_all.huber_sigma = 1e6;
  const FrameMotion all = estimate_frame_motion(f.a, f.b, Eigen::Isometry3d::Identity(), keep_all);
  ASSERT_TRUE(all.ok());
  EXPECT_GT((all.T_a_b.translation() - T.translation()).norm(), 1.5 * error_m);
}

TEST(FrameMotion, LeavesOutFeaturesThatHoldStillInTheImage) {
  // A third of the features are corners of the shading the robot's own lamp casts on a plain
  // wall: the same pixel in both frames, with the wall's depth. The guess is the window's, 20 %
  // short, as it is where the lidar cannot see the motion.
  std::mt19937 rng(5);
  const Eigen::Isometry3d T = forward_motion();
  Frames f = make_frames(T, 100, 0.3, rng);
  std::uniform_real_distribution<double> where(-0.4, 0.4);
  for (int k = 0; k < 50; ++k) {
    const auto id = static_cast<std::uint64_t>(1000 + k);
    const Eigen::Vector2d at(where(rng), where(rng));
    f.a.push_back({id, at, 1.5});
    f.b.push_back({id, at, 1.5});
  }
  Eigen::Isometry3d guess = T;
  guess.translation() *= 0.8;
  const FrameMotion with = estimate_frame_motion(f.a, f.b, guess, config());
  FrameMotionConfig off = config();
  off.still_flow_sigma = 0;
  const FrameMotion without = estimate_frame_motion(f.a, f.b, guess, off);
  ASSERT_TRUE(with.ok());
  ASSERT_TRUE(without.ok());
  // Of their 100 observations nearly all; of the world's 200 a few near the focus of expansion.
  EXPECT_GE(with.still, 90);
  EXPECT_LE(with.still, 110);
  EXPECT_LT((with.T_a_b.translation() - T.translation()).norm(), 0.004);
  EXPECT_EQ(without.still, 0);
  EXPECT_GT((without.T_a_b.translation() - T.translation()).norm(), 0.01);
}

TEST(FrameMotion, EdgesWeighOnlyAcrossThemselves) {
  // Two thirds of the features sit on straight edges that run along their own flow (a
  // corridor's edges run towards the focus of expansion): KLT cannot see motion along them, and
  // their tracks in frame b have moved only 80 % of the flow. Across the edge they are right.
  // Weighed by their patches' shape they say nothing along the edge; weighed as corners they pull
  // the motion short.
  std::mt19937 rng(7);
  Eigen::Isometry3d T = forward_motion();
  T.linear().setIdentity();
  Frames f = make_frames(T, 160, 0.3, rng);
  for (std::size_t k = 0; k < f.a.size(); ++k) {
    if (k % 3 == 0) continue;
    const Eigen::Vector2d flow = f.b[k].normalised - f.a[k].normalised;
    if (flow.norm() < 1e-6) continue;
    const Eigen::Vector2d along = flow.normalized();
    f.b[k].normalised = f.a[k].normalised + 0.8 * flow;
    f.b[k].depth_m = std::numeric_limits<double>::quiet_NaN();  // depth from frame a only
    // The patch fixes the position across the edge only.
    const Eigen::Vector2d across(-along.y(), along.x());
    const Eigen::Matrix2d shape = across * across.transpose() + 1e-4 * along * along.transpose();
    f.a[k].patch_shape = f.b[k].patch_shape = shape;
  }
  Eigen::Isometry3d guess = T;
  guess.translation() *= 0.9;
  FrameMotionConfig shaped = config();
  shaped.fix_rotation = true;
  shaped.aperture_max_ratio = 30;
  FrameMotionConfig corners = shaped;
  corners.aperture_max_ratio = 0;
  const FrameMotion with = estimate_frame_motion(f.a, f.b, guess, shaped);
  const FrameMotion without = estimate_frame_motion(f.a, f.b, guess, corners);
  ASSERT_TRUE(with.ok());
  ASSERT_TRUE(without.ok());
  EXPECT_LT((with.T_a_b.translation() - T.translation()).norm(), 0.004);
  EXPECT_GT((without.T_a_b.translation() - T.translation()).norm(), 0.01);
  // Corners weigh as before: the same motion with or without the shapes' weighting.
  std::mt19937 rng2(8);
  const Frames clean = make_frames(T, 160, 0.3, rng2);
  const FrameMotion a = estimate_frame_motion(clean.a, clean.b, guess, shaped);
  const FrameMotion b = estimate_frame_motion(clean.a, clean.b, guess, corners);
  ASSERT_TRUE(a.ok());
  ASSERT_TRUE(b.ok());
  EXPECT_LT((a.T_a_b.translation() - b.T_a_b.translation()).norm(), 1e-9);
}

TEST(FrameMotion, AGuessTwiceTooFastLeavesNoFeatureOut) {
  // A speed estimate gone to twice the truth puts every feature of the world nearer to where it
  // was than to where the guess moves it; leaving them out would keep the guess. The majority
  // failing the test says the guess is wrong, and the motion comes from all of them.
  std::mt19937 rng(6);
  Eigen::Isometry3d T = forward_motion();
  T.linear().setIdentity();  // a straight drive: the flow is the translation's alone
  const Frames f = make_frames(T, 100, 0.3, rng);
  Eigen::Isometry3d guess = T;
  guess.translation() *= 2.5;
  const FrameMotion m = estimate_frame_motion(f.a, f.b, guess, config());
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m.still, 0);
  EXPECT_LT((m.T_a_b.translation() - T.translation()).norm(), 0.004);
}

TEST(FrameMotion, CovarianceMatchesTheSpreadOfEstimates) {
  const Eigen::Isometry3d T = forward_motion();
  std::mt19937 rng(5);
  Eigen::Matrix<double, 6, 6> sum = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> predicted = Eigen::Matrix<double, 6, 6>::Zero();
  const int runs = 300;
  for (int r = 0; r < runs; ++r) {
    const Frames f = make_frames(T, 60, 1.0, rng);
    FrameMotionConfig c = config();
    c.pixel_sigma = std::sqrt(2.0) / kFocalPx;  // each residual holds two observations' noise
    c.outlier_sigma = 10;                       // pure Gaussian noise: nothing to reject
    const FrameMotion m = estimate_frame_motion(f.a, f.b, T, c);
    ASSERT_TRUE(m.ok());
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = so3::log(Eigen::Matrix3d(T.linear().transpose() * m.T_a_b.linear()));
    e.tail<3>() = T.linear().transpose() * (m.T_a_b.translation() - T.translation());
    sum += e * e.transpose();
    predicted += m.covariance;
  }
  sum /= runs;
  predicted /= runs;
  // Both directions use the same features, so the Hessian counts each pair's information about
  // twice: the spread is larger than predicted, by at most ~2x in variance.
  for (int i = 0; i < 6; ++i) {
    EXPECT_GT(sum(i, i), 0.5 * predicted(i, i)) << i;
    EXPECT_LT(sum(i, i), 3.0 * predicted(i, i)) << i;
  }
}

TEST(FrameMotion, TooFewFeaturesWithDepthGiveNothing) {
  std::mt19937 rng(6);
  const Frames f = make_frames(forward_motion(), 100, 0.5, rng, 25);  // 4 + 4 with depth
  const FrameMotion m = estimate_frame_motion(f.a, f.b, Eigen::Isometry3d::Identity(), config());
  EXPECT_FALSE(m.ok());
  EXPECT_EQ(m.status, FrameMotionStatus::kTooFewPoints);
}

/// `moving` features that move with the world and `fixed` ones that hold still in the image (a
/// thermal camera's fixed pattern), appended after them.
Frames with_fixed_pattern(const Eigen::Isometry3d& T, int moving, int fixed, std::mt19937& rng) {
  Frames f = make_frames(T, moving, 0.3, rng);
  const Frames still = make_frames(Eigen::Isometry3d::Identity(), fixed, 0.3, rng);
  for (std::size_t k = 0; k < still.a.size(); ++k) {
    FrameFeature a = still.a[k], b = still.b[k];
    a.id = b.id = 1000 + k;
    f.a.push_back(a);
    f.b.push_back(b);
  }
  return f;
}

TEST(FrameMotion, AStrictGateIgnoresAStillMajority) {
  std::mt19937 rng(7);
  const Eigen::Isometry3d T = forward_motion();
  const Frames f = with_fixed_pattern(T, 40, 100, rng);
  FrameMotionConfig c = config();
  c.guess_gate = 3.0 / kFocalPx;
  c.still_flow_sigma = 0;  // the gate alone (the still test is LeavesOutFeaturesThatHoldStill)
  // The guess (the IMU's) is right: the moving minority passes the gate, the still majority not.
  c.gate_falls_back = false;
  const FrameMotion strict = estimate_frame_motion(f.a, f.b, T, c);
  ASSERT_TRUE(strict.ok());
  EXPECT_LT((strict.T_a_b.translation() - T.translation()).norm(), 0.004);
  // Falling back, the majority decides: the camera stood still.
  c.gate_falls_back = true;
  const FrameMotion lenient = estimate_frame_motion(f.a, f.b, T, c);
  ASSERT_TRUE(lenient.ok());
  EXPECT_GT((lenient.T_a_b.translation() - T.translation()).norm(), 0.05);
}

TEST(FrameMotion, AStrictGateWithTooFewInsideGivesNothing) {
  std::mt19937 rng(8);
  const Eigen::Isometry3d T = forward_motion();
  const Frames f = with_fixed_pattern(T, 5, 100, rng);
  FrameMotionConfig c = config();
  c.guess_gate = 3.0 / kFocalPx;
  c.gate_falls_back = false;
  const FrameMotion m = estimate_frame_motion(f.a, f.b, T, c);
  EXPECT_FALSE(m.ok());
  EXPECT_EQ(m.status, FrameMotionStatus::kTooFewInliers);
}

}  // namespace
}  // namespace posed::fusion
