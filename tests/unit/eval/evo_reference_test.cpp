// The figures evo reports on its own test data (shared/realdata/trajectories, README there):
// APE, translation part, SE(3) Umeyama alignment. KITTI files have no stamps: pose i ↔ pose i.
// TUM fr1/xyz is a regression value computed independently with numpy (evo's association,
// Umeyama and statistics written out directly in Python; see the eval helper's report).

#include <gtest/gtest.h>

#include "eval_test_util.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/eval/trajectory_io.hpp"

namespace posed::eval {
namespace {

std::filesystem::path trajectories_dir() {
  const auto root = test::realdata_dir();
  return root.empty() ? root : root / "trajectories";
}

#define REQUIRE_TRAJECTORIES()                                                                \
  const auto dir = trajectories_dir();                                                        \
  if (dir.empty() || !std::filesystem::exists(dir / "KITTI_00_gt.txt")) {                     \
    GTEST_SKIP() << "real data absent: set POSED_REALDATA or put shared/realdata beside the " \
                    "source tree (needs trajectories/)";                                      \
  }

EvalResult evaluate_files(const std::filesystem::path& gt, const std::filesystem::path& est,
                          const EvalOptions& options = {}) {
  return evaluate(read_trajectory(gt.string()), read_trajectory(est.string()), options);
}

TEST(EvoReference, Kitti00OrbSlam2ApeRmse) {
  REQUIRE_TRAJECTORIES();
  const EvalResult r = evaluate_files(dir / "KITTI_00_gt.txt", dir / "KITTI_00_ORB.txt");
  EXPECT_TRUE(r.association.by_index);
  EXPECT_EQ(r.ate_m.count, 4541u);
  EXPECT_NEAR(r.ate_m.rmse, 1.3034497146, 1e-6);
}

TEST(EvoReference, Kitti00SPtamApeRmse) {
  REQUIRE_TRAJECTORIES();
  const EvalResult r = evaluate_files(dir / "KITTI_00_gt.txt", dir / "KITTI_00_SPTAM.txt");
  EXPECT_EQ(r.ate_m.count, 4541u);
  EXPECT_NEAR(r.ate_m.rmse, 3.7384879076, 1e-6);
}

TEST(EvoReference, Kitti00OrbSlam2RpeBy100mMatchesNumpy) {
  REQUIRE_TRAJECTORIES();
  const EvalResult r = evaluate_files(dir / "KITTI_00_gt.txt", dir / "KITTI_00_ORB.txt");
  ASSERT_TRUE(r.rpe_by_distance.skipped_reason.empty()) << r.rpe_by_distance.skipped_reason;
  EXPECT_EQ(r.rpe_by_distance.pairs, 36u);
  EXPECT_NEAR(r.rpe_by_distance.translation_m.rmse, 1.1869395623, 1e-6);
  EXPECT_NEAR(r.rpe_by_distance.translation_m.max, 2.5754673516, 1e-6);
  EXPECT_EQ(r.rpe_by_time.skipped_reason, "no stamps (kitti)");
}

TEST(EvoReference, TumFr1XyzRgbdSlamWithAssociation) {
  REQUIRE_TRAJECTORIES();
  EvalOptions o;
  o.rpe_delta_m = 0.5;
  const EvalResult r =
      evaluate_files(dir / "freiburg1_xyz-groundtruth.txt", dir / "freiburg1_xyz-rgbdslam.txt", o);
  EXPECT_FALSE(r.association.by_index);
  EXPECT_EQ(r.association.size(), 785u);
  EXPECT_EQ(r.association.duplicates_dropped, 0u);
  EXPECT_NEAR(r.ate_m.rmse, 0.0134700888, 1e-9);
  EXPECT_NEAR(r.ate_m.mean, 0.0120244987, 1e-9);
  EXPECT_NEAR(r.ate_m.median, 0.0111831868, 1e-9);
  EXPECT_NEAR(r.ate_m.std, 0.0060708092, 1e-9);
  EXPECT_NEAR(r.ate_m.min, 0.0009550462, 1e-9);
  EXPECT_NEAR(r.ate_m.max, 0.0347595459, 1e-9);
  EXPECT_EQ(r.rpe_by_distance.pairs, 14u);
  EXPECT_NEAR(r.rpe_by_distance.translation_m.rmse, 0.0348803925, 1e-9);
  EXPECT_NEAR(r.rpe_by_distance.rotation_deg.rmse, 1.6266063075, 1e-7);
  EXPECT_EQ(r.rpe_by_time.pairs, 26u);
  EXPECT_NEAR(r.rpe_by_time.translation_m.rmse, 0.0215916175, 1e-9);
  EXPECT_NEAR(r.rpe_by_time.rotation_deg.rmse, 0.8300682871, 1e-7);
}

}  // namespace
}  // namespace posed::eval
