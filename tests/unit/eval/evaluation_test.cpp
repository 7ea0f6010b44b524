#include "tools/eval/evaluation.hpp"

#include <gtest/gtest.h>

#include "eval_test_util.hpp"
#include "tools/eval/eval_error.hpp"
#include "tools/eval/report.hpp"

namespace posed::eval {
namespace {

EvalOptions options(Alignment a) {
  EvalOptions o;
  o.alignment = a;
  o.rpe_delta_m = 2.0;
  o.rpe_delta = Duration::from_s(1);
  return o;
}

TEST(Evaluation, AlignNoneOnIdenticalTrajectoriesIsZero) {
  const Trajectory gt = test::wavy_trajectory("gt.txt", 30.0);
  Trajectory est = gt;
  est.source = "est.txt";
  const EvalResult r = evaluate(gt, est, options(Alignment::kNone));
  EXPECT_EQ(r.association.size(), gt.size());
  EXPECT_EQ(r.ate_m.count, gt.size());
  EXPECT_EQ(r.ate_m.rmse, 0.0);
  EXPECT_EQ(r.ate_m.max, 0.0);
  ASSERT_TRUE(r.rpe_by_distance.skipped_reason.empty()) << r.rpe_by_distance.skipped_reason;
  ASSERT_TRUE(r.rpe_by_time.skipped_reason.empty()) << r.rpe_by_time.skipped_reason;
  EXPECT_GT(r.rpe_by_distance.pairs, 5u);
  EXPECT_EQ(r.rpe_by_time.pairs, 30u);  // boundaries at 0, 1, ..., 30 s
  EXPECT_EQ(r.rpe_by_distance.translation_m.max, 0.0);
  EXPECT_EQ(r.rpe_by_time.translation_m.max, 0.0);
  EXPECT_NEAR(r.rpe_by_time.rotation_deg.max, 0.0, 1e-12);
}

TEST(Evaluation, AlignmentRemovesAKnownTransformAndSim3AlsoTheScale) {
  const Trajectory gt = test::wavy_trajectory("gt.txt", 20.0);
  // The estimate: the same motion expressed in another world frame, at 1/3 scale.
  Sim3 T_est_gt;
  T_est_gt.R_gt_est = test::rot(0.5, -0.2, 1.7);
  T_est_gt.t_gt_est_m = Eigen::Vector3d(4, 5, -6);
  T_est_gt.scale = 1.0 / 3.0;
  Trajectory est = gt;
  est.source = "est.txt";
  for (std::size_t i = 0; i < est.size(); ++i) {
    est.p_world_m[i] = T_est_gt.apply(gt.p_world_m[i]);
    est.R_world_body[i] = T_est_gt.R_gt_est * gt.R_world_body[i];
  }
  const EvalResult none = evaluate(gt, est, options(Alignment::kNone));
  EXPECT_GT(none.ate_m.rmse, 1.0);
  const EvalResult se3 = evaluate(gt, est, options(Alignment::kSE3));
  EXPECT_GT(se3.ate_m.rmse, 0.1);  // the scale is left
  const EvalResult sim3 = evaluate(gt, est, options(Alignment::kSim3));
  EXPECT_NEAR(sim3.ate_m.rmse, 0.0, 1e-9);
  EXPECT_NEAR(sim3.T_gt_est.scale, 3.0, 1e-9);
  // With the scale undone the relative motions agree too.
  EXPECT_NEAR(sim3.rpe_by_time.translation_m.max, 0.0, 1e-9);
  EXPECT_NEAR(sim3.rpe_by_time.rotation_deg.max, 0.0, 1e-9);
}

TEST(Evaluation, FewerThanThreeAssociatedPosesIsAnError) {
  const Trajectory gt = test::wavy_trajectory("gt.txt", 5.0);
  Trajectory est = gt;
  est.source = "est.txt";
  EvalOptions o = options(Alignment::kSE3);
  o.association.est_offset = Duration::from_s(1000);  // nothing overlaps
  try {
    evaluate(gt, est, o);
    FAIL() << "evaluated without associated poses";
  } catch (const EvalError& e) {
    EXPECT_NE(std::string(e.what()).find("only 0 associated poses between gt.txt and est.txt"),
              std::string::npos)
        << e.what();
  }
}

TEST(Evaluation, DegenerateAlignmentIsAnErrorButAlignNoneWorks) {
  Trajectory gt;
  gt.source = "gt.txt";
  for (int i = 0; i < 10; ++i) test::add_pose(gt, i, Eigen::Vector3d(i, 0, 0));  // a line
  Trajectory est = gt;
  est.source = "est.txt";
  EXPECT_THROW(evaluate(gt, est, options(Alignment::kSE3)), EvalError);
  EXPECT_EQ(evaluate(gt, est, options(Alignment::kNone)).ate_m.rmse, 0.0);
}

TEST(Evaluation, PositionsOnlyGroundTruthSkipsRpeSayingWhy) {
  Trajectory gt = test::wavy_trajectory("m2dgr.txt", 10.0);
  Trajectory est = gt;
  est.source = "est.txt";
  gt.has_orientation = false;
  const EvalResult r = evaluate(gt, est, options(Alignment::kSE3));
  EXPECT_EQ(r.ate_m.count, gt.size());
  EXPECT_EQ(r.rpe_by_distance.skipped_reason, "m2dgr.txt has positions only (zero quaternions)");
  EXPECT_EQ(r.rpe_by_time.skipped_reason, "m2dgr.txt has positions only (zero quaternions)");
}

TEST(Evaluation, ReportsCarryUnits) {
  const Trajectory gt = test::wavy_trajectory("gt.txt", 10.0);
  Trajectory est = gt;
  est.source = "est \"quoted\".txt";
  const EvalResult r = evaluate(gt, est, options(Alignment::kSE3));
  const std::string table = format_table(gt, est, r);
  EXPECT_NE(table.find("ATE translation [m]"), std::string::npos) << table;
  EXPECT_NE(table.find("RPE 2 m translation [m]"), std::string::npos) << table;
  EXPECT_NE(table.find("RPE 1 s rotation [deg]"), std::string::npos) << table;
  const std::string json = format_json(gt, est, r);
  EXPECT_NE(json.find("\"translation_m\": {\"count\": 101"), std::string::npos) << json;
  EXPECT_NE(json.find("\"file\": \"est \\\"quoted\\\".txt\""), std::string::npos) << json;
}

}  // namespace
}  // namespace posed::eval
