#include "tools/eval/association.hpp"

#include <gtest/gtest.h>

#include "eval_test_util.hpp"
#include "tools/eval/eval_error.hpp"

namespace posed::eval {
namespace {

using test::add_pose;

Trajectory stamped(const std::string& name, const std::vector<double>& stamps_s) {
  Trajectory t;
  t.source = name;
  for (double s : stamps_s) add_pose(t, s, Eigen::Vector3d(s, 0, 0));
  return t;
}

TEST(Association, NearestWithinToleranceAndDroppedBeyond) {
  // Ground truth at 100 Hz, estimate at ~30 Hz with jitter; 2.3 has no ground truth near it.
  const Trajectory gt = stamped("gt", {1.00, 1.01, 1.02, 1.03, 1.04, 1.05, 1.06, 1.07});
  const Trajectory est = stamped("est", {1.004, 1.036, 1.0649, 2.3});
  const Association a = associate(gt, est, {Duration::from_ms(5), Duration::from_ns(0)});
  EXPECT_FALSE(a.by_index);
  EXPECT_EQ(a.gt_index, (std::vector<std::size_t>{0, 4, 6}));
  EXPECT_EQ(a.est_index, (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(a.beyond_max_diff, 1u);
  EXPECT_EQ(a.duplicates_dropped, 0u);
  EXPECT_EQ(a.max_abs_diff, Duration::from_us(4900));

  // Tightening the tolerance below 4.9 ms drops 1.0649 ↔ 1.06 too; the boundary is inclusive.
  const Association tight = associate(gt, est, {Duration::from_us(4900), Duration::from_ns(0)});
  EXPECT_EQ(tight.size(), 3u);
  const Association tighter = associate(gt, est, {Duration::from_us(4899), Duration::from_ns(0)});
  EXPECT_EQ(tighter.size(), 2u);
  EXPECT_EQ(tighter.beyond_max_diff, 2u);
}

TEST(Association, OffsetShiftsEstimateStamps) {
  // The estimate's clock runs 0.5 s behind: without the offset nothing matches.
  const Trajectory gt = stamped("gt", {10.0, 10.1, 10.2, 10.3, 10.4});
  const Trajectory est = stamped("est", {9.5, 9.7, 9.9});
  EXPECT_EQ(associate(gt, est, {Duration::from_ms(10), Duration::from_ns(0)}).size(), 0u);
  const Association a = associate(gt, est, {Duration::from_ms(10), Duration::from_ms(500)});
  EXPECT_EQ(a.gt_index, (std::vector<std::size_t>{0, 2, 4}));
  EXPECT_EQ(a.est_index, (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(a.max_abs_diff, Duration::from_ns(0));
}

TEST(Association, OffsetAppliesWhenTheEstimateIsTheLongerOne) {
  // The estimate has more poses, so the ground truth is walked; the offset still shifts the
  // estimate (evo negates it internally in this case).
  const Trajectory gt = stamped("gt", {20.0, 20.2, 20.4});
  const Trajectory est = stamped("est", {19.0, 19.1, 19.2, 19.3, 19.4, 19.5});
  const Association a = associate(gt, est, {Duration::from_ms(10), Duration::from_s(1)});
  EXPECT_EQ(a.gt_index, (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(a.est_index, (std::vector<std::size_t>{0, 2, 4}));
}

TEST(Association, EachPoseIsMatchedAtMostOnceAndTheCloserKeepsIt) {
  // Two ground-truth stamps pick estimate stamp 5.0; the closer (5.003) keeps it.
  // Walked is gt (3 poses < 4).
  const Trajectory gt_sorted = stamped("gt", {4.994, 5.003, 7.0});
  const Trajectory est = stamped("est", {1.0, 5.0, 7.0, 9.0});
  const Association a = associate(gt_sorted, est, {Duration::from_ms(10), Duration::from_ns(0)});
  EXPECT_EQ(a.gt_index, (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(a.est_index, (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(a.duplicates_dropped, 1u);
  EXPECT_EQ(a.beyond_max_diff, 0u);

  // On an exact tie the earlier stamp keeps the match.
  const Trajectory tie = stamped("gt", {4.997, 5.003, 7.0});
  const Association b = associate(tie, est, {Duration::from_ms(10), Duration::from_ns(0)});
  EXPECT_EQ(b.gt_index, (std::vector<std::size_t>{0, 2}));
  EXPECT_EQ(b.duplicates_dropped, 1u);
}

TEST(Association, NearestTieBetweenTwoCandidatesTakesTheEarlier) {
  const Trajectory gt = stamped("gt", {1.0, 1.2, 1.4, 1.6});
  const Trajectory est = stamped("est", {1.1, 1.5});
  const Association a = associate(gt, est, {Duration::from_ms(100), Duration::from_ns(0)});
  EXPECT_EQ(a.gt_index, (std::vector<std::size_t>{0, 2}));
}

TEST(Association, UnstampedFilesPairByIndexAndMustMatchInLength) {
  Trajectory gt, est;
  gt.source = "gt.txt";
  est.source = "est.txt";
  gt.format = est.format = TrajectoryFormat::kKitti;
  for (int i = 0; i < 4; ++i) {
    gt.p_world_m.emplace_back(i, 0, 0);
    gt.R_world_body.push_back(Eigen::Matrix3d::Identity());
  }
  est = gt;
  est.source = "est.txt";
  const Association a = associate(gt, est);
  EXPECT_TRUE(a.by_index);
  EXPECT_EQ(a.gt_index, (std::vector<std::size_t>{0, 1, 2, 3}));
  EXPECT_EQ(a.est_index, a.gt_index);

  est.p_world_m.pop_back();
  est.R_world_body.pop_back();
  EXPECT_THROW(associate(gt, est), EvalError);

  const Trajectory tum = stamped("tum.txt", {1, 2, 3, 4});
  try {
    associate(gt, tum);
    FAIL() << "a KITTI and a TUM file were associated";
  } catch (const EvalError& e) {
    EXPECT_NE(std::string(e.what()).find("one has stamps and the other has none"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace posed::eval
