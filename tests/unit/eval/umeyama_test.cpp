#include "tools/eval/umeyama.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "eval_test_util.hpp"
#include "tools/eval/eval_error.hpp"

namespace posed::eval {
namespace {

std::vector<Eigen::Vector3d> cloud() {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 50; ++i) {
    const double s = 0.2 * i;
    p.emplace_back(3.0 * std::cos(s) + 0.1 * s, 2.0 * std::sin(1.3 * s), 0.7 * std::sin(0.4 * s));
  }
  return p;
}

std::vector<Eigen::Vector3d> transformed(const std::vector<Eigen::Vector3d>& p, const Sim3& T) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& x : p) out.push_back(T.apply(x));
  return out;
}

TEST(Umeyama, RecoversAKnownSE3) {
  Sim3 truth;
  truth.R_gt_est = test::rot(0.3, -1.1, 2.5);
  truth.t_gt_est_m = Eigen::Vector3d(10.0, -4.0, 2.5);
  const auto p_est = cloud();
  const Sim3 T = umeyama(p_est, transformed(p_est, truth), false);
  EXPECT_NEAR((T.R_gt_est - truth.R_gt_est).norm(), 0.0, 1e-12);
  EXPECT_NEAR((T.t_gt_est_m - truth.t_gt_est_m).norm(), 0.0, 1e-12);
  EXPECT_EQ(T.scale, 1.0);
}

TEST(Umeyama, RecoversAKnownSim3) {
  Sim3 truth;
  truth.R_gt_est = test::rot(-0.4, 0.2, -2.0);
  truth.t_gt_est_m = Eigen::Vector3d(-1.0, 7.0, 0.25);
  truth.scale = 2.75;  // a monocular estimate in units 2.75 times smaller than metres
  const auto p_est = cloud();
  const Sim3 T = umeyama(p_est, transformed(p_est, truth), true);
  EXPECT_NEAR((T.R_gt_est - truth.R_gt_est).norm(), 0.0, 1e-12);
  EXPECT_NEAR((T.t_gt_est_m - truth.t_gt_est_m).norm(), 0.0, 1e-11);
  EXPECT_NEAR(T.scale, truth.scale, 1e-12);
  // SE(3) on the same data cannot absorb the scale: it leaves a residual.
  const Sim3 rigid = umeyama(p_est, transformed(p_est, truth), false);
  EXPECT_EQ(rigid.scale, 1.0);
  double residual = 0.0;
  const auto p_gt = transformed(p_est, truth);
  for (std::size_t i = 0; i < p_est.size(); ++i)
    residual += (rigid.apply(p_est[i]) - p_gt[i]).norm();
  EXPECT_GT(residual / static_cast<double>(p_est.size()), 0.5);
}

TEST(Umeyama, PlanarPointsAreEnough) {
  // A ground robot's trajectory lies in a plane: the cross-covariance has rank 2 and the
  // rotation is still unique (the reflection fix picks the proper one).
  std::vector<Eigen::Vector3d> p_est;
  for (int i = 0; i < 20; ++i) p_est.emplace_back(std::cos(0.3 * i), 2.0 * std::sin(0.3 * i), 0.0);
  Sim3 truth;
  truth.R_gt_est = test::rot(0.0, 0.0, 1.0);
  truth.t_gt_est_m = Eigen::Vector3d(1, 2, 3);
  const Sim3 T = umeyama(p_est, transformed(p_est, truth), false);
  EXPECT_NEAR((T.R_gt_est - truth.R_gt_est).norm(), 0.0, 1e-12);
  EXPECT_NEAR(T.R_gt_est.determinant(), 1.0, 1e-12);
}

TEST(Umeyama, CollinearOrTooFewPointsAreDegenerate) {
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 10; ++i) line.emplace_back(0.5 * i, 0.25 * i, 0.0);
  try {
    umeyama(line, line, false);
    FAIL() << "collinear points gave a rotation";
  } catch (const EvalError& e) {
    EXPECT_NE(std::string(e.what()).find("degenerate alignment"), std::string::npos);
  }
  const std::vector<Eigen::Vector3d> same(5, Eigen::Vector3d(1, 2, 3));
  EXPECT_THROW(umeyama(same, same, true), EvalError);
  const std::vector<Eigen::Vector3d> two = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0)};
  EXPECT_THROW(umeyama(two, two, false), EvalError);
}

}  // namespace
}  // namespace posed::eval
