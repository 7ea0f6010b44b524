#include "tools/eval/rpe.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "eval_test_util.hpp"

namespace posed::eval {
namespace {

TEST(RpePairs, ByPathLengthFollowsEvo) {
  // Poses 1 m apart on a line: with delta 2.5 m the path reaches 3 m at poses 3, 6, 9 (evo
  // starts the first pair where the path first reaches delta, not at pose 0).
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 11; ++i) p.emplace_back(i, 0, 0);
  EXPECT_EQ(pairs_by_path_length(p, 2.5), (std::vector<IndexPair>{{3, 6}, {6, 9}}));
  EXPECT_EQ(pairs_by_path_length(p, 1.0),
            (std::vector<IndexPair>{
                {1, 2}, {2, 3}, {3, 4}, {4, 5}, {5, 6}, {6, 7}, {7, 8}, {8, 9}, {9, 10}}));
  EXPECT_TRUE(pairs_by_path_length(p, 20.0).empty());
}

TEST(RpePairs, ByTimeStartsAtTheFirstPose) {
  std::vector<TrajectoryTime> stamps;
  for (int i = 0; i < 10; ++i)
    stamps.push_back(TrajectoryTime::from_ns(Duration::from_ms(300).ns * i));
  // 0, 0.3, ..., 2.7 s; delta 1 s: boundaries at 0, 1.2 (first >= 1 s after 0), 2.4.
  EXPECT_EQ(pairs_by_time(stamps, Duration::from_s(1)), (std::vector<IndexPair>{{0, 4}, {4, 8}}));
  EXPECT_EQ(pairs_by_time(stamps, Duration::from_ms(900)),
            (std::vector<IndexPair>{{0, 3}, {3, 6}, {6, 9}}));
}

TEST(Rpe, ConstantDriftGivesAConstantError) {
  // Ground truth drives a circle of radius 20 m at 1 m/s (yaw follows the heading). The
  // estimate overestimates the speed by 2 % and its heading drifts 0.5 deg per metre travelled,
  // constant, in the body frame: every relative motion over L metres of path is then off by the
  // same amount, so RPE is constant and equals the error of one segment computed in closed form.
  const double radius_m = 20.0;
  const double scale_err = 1.02;
  const double drift_rad_per_m = 0.5 * std::numbers::pi / 180.0;
  std::vector<RigidPose> gt, est;
  std::vector<Eigen::Vector3d> p_gt;
  const int n = 1000;
  const double step_m = 0.1;
  // Integrate both in their own body frames so the drift is constant per step.
  Eigen::Matrix3d R_gt = Eigen::Matrix3d::Identity(), R_est = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_g = Eigen::Vector3d::Zero(), p_e = Eigen::Vector3d::Zero();
  const Eigen::Matrix3d dR_gt = test::rot(0, 0, step_m / radius_m);
  const Eigen::Matrix3d dR_est = test::rot(0, 0, step_m / radius_m + step_m * drift_rad_per_m);
  for (int i = 0; i < n; ++i) {
    gt.push_back({R_gt, p_g});
    est.push_back({R_est, p_e});
    p_gt.push_back(p_g);
    p_g += R_gt * Eigen::Vector3d(step_m, 0, 0);
    p_e += R_est * Eigen::Vector3d(step_m * scale_err, 0, 0);
    R_gt = R_gt * dR_gt;
    R_est = R_est * dR_est;
  }
  // Pairs 50 steps apart (5 m of arc) by index, so every pair spans the same motion.
  std::vector<IndexPair> pairs;
  for (int i = 0; i + 50 < n; i += 50) pairs.emplace_back(i, i + 50);
  const RpeErrors e = relative_pose_errors(gt, est, pairs);
  ASSERT_EQ(e.translation_m.size(), pairs.size());

  // Closed form of one segment: the same 50-step recursion from the identity.
  Eigen::Matrix3d Rg = Eigen::Matrix3d::Identity(), Re = Eigen::Matrix3d::Identity();
  Eigen::Vector3d pg = Eigen::Vector3d::Zero(), pe = Eigen::Vector3d::Zero();
  for (int k = 0; k < 50; ++k) {
    pg += Rg * Eigen::Vector3d(step_m, 0, 0);
    pe += Re * Eigen::Vector3d(step_m * scale_err, 0, 0);
    Rg = Rg * dR_gt;
    Re = Re * dR_est;
  }
  const double expected_t_m = (pe - pg).norm();
  const double expected_rot_deg = 50 * step_m * 0.5;  // 0.5 deg per metre, 5 m
  EXPECT_GT(expected_t_m, 0.1);                       // a real error, not a trivially zero one
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    EXPECT_NEAR(e.translation_m[k], expected_t_m, 1e-9) << "pair " << k;
    EXPECT_NEAR(e.rotation_deg[k], expected_rot_deg, 1e-9) << "pair " << k;
  }
}

TEST(Rpe, ARigidlyMovedEstimateHasNoRelativeError) {
  // RPE does not see a global transform: the same trajectory in another world frame scores 0.
  const Trajectory t = test::wavy_trajectory("t", 10.0);
  const Eigen::Matrix3d R = test::rot(0.2, 0.4, -1.0);
  const Eigen::Vector3d off(5, -3, 1);
  std::vector<RigidPose> gt, est;
  for (std::size_t i = 0; i < t.size(); ++i) {
    gt.push_back({t.R_world_body[i], t.p_world_m[i]});
    est.push_back({R * t.R_world_body[i], R * t.p_world_m[i] + off});
  }
  const RpeErrors e = relative_pose_errors(gt, est, pairs_by_path_length(t.p_world_m, 1.0));
  ASSERT_FALSE(e.translation_m.empty());
  for (double v : e.translation_m) EXPECT_NEAR(v, 0.0, 1e-12);
  for (double v : e.rotation_deg) EXPECT_NEAR(v, 0.0, 1e-9);
}

}  // namespace
}  // namespace posed::eval
