// Scan-to-map on simulated scans: recovering a known pose from an offset guess, the Eigen
// Gauss-Newton agreeing with Ceres on the same problem, and degeneracy found along a corridor's
// axis but not in a street.

#include "core/lidar/scan_matcher.hpp"

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <gtest/gtest.h>

#include "core/lidar/lidar_odometry.hpp"
#include "core/math/so3.hpp"
#include "tests/unit/lidar/sim_fixture.hpp"

namespace posed::lidar {
namespace {

using test::true_motion;

/// A map from scan `map_scan` at its true pose, and scan `query_scan` deskewed and ready.
struct Scene {
  LidarOdometry odom{LidarOdometryConfig{}};
  Eigen::Isometry3d truth;
};

void prepare(const std::string& scenario, std::size_t map_scan, std::size_t query_scan,
             LidarOdometry& odom, Eigen::Isometry3d& truth) {
  const sim::LidarImuRun& run = test::simulated(scenario, 6.0);
  const sim::DecodedScan& a = run.scans.at(map_scan);
  odom.deskew(a.points, a.start, true_motion(run, a));
  odom.extract_features();
  odom.match(run.T_map_lidar(a.end));
  odom.commit(run.T_map_lidar(a.end));
  const sim::DecodedScan& b = run.scans.at(query_scan);
  odom.deskew(b.points, b.start, true_motion(run, b));
  odom.extract_features();
  truth = run.T_map_lidar(b.end);
}

Eigen::Matrix<double, 6, 1> offset(double deg, double m) {
  Eigen::Matrix<double, 6, 1> d;
  d << 0.3 * deg, -0.5 * deg, deg, m, -0.7 * m, 0.3 * m;
  d.head<3>() *= M_PI / 180;
  return d;
}

double rotation_error_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return so3::log(Eigen::Matrix3d(a.linear().transpose() * b.linear())).norm() * 180 / M_PI;
}

TEST(ScanMatcher, RecoversTheTruePoseFromAnOffsetGuess) {
  for (const std::string scenario : {"room", "street_night", "mine"}) {
    for (const std::size_t query : {30u, 33u}) {  // the map's own scan, then the next but two
      LidarOdometryConfig config;
      LidarOdometry odom(config);
      Eigen::Isometry3d truth;
      prepare(scenario, 30, query, odom, truth);
      const ScanMatchResult r = odom.match(retract(truth, offset(2.0, 0.3)));
      ASSERT_TRUE(r.ok) << scenario;
      // The map holds one scan, voxel-thinned: centimetres, tenths of a degree.
      EXPECT_LT((r.T_map_lidar.translation() - truth.translation()).norm(), 0.03)
          << scenario << " scan " << query;
      EXPECT_LT(rotation_error_deg(r.T_map_lidar, truth), 0.25) << scenario << " scan " << query;
      EXPECT_GT(r.plane_correspondences, 100u);
    }
  }
}

// The same residuals as normal_equations(), for Ceres.
struct PointResidual {
  Correspondence c;
  template <class T>
  bool operator()(const T* q_xyzw, const T* t, T* out) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_xyzw);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> tr(t);
    const Eigen::Matrix<T, 3, 1> e = q * c.p_lidar.cast<T>() + tr - c.anchor.cast<T>();
    if (c.is_plane) {
      out[0] = c.direction.cast<T>().dot(e);
      out[1] = out[2] = T(0);
    } else {
      const Eigen::Matrix<T, 3, 1> r = e - c.direction.cast<T>() * c.direction.cast<T>().dot(e);
      out[0] = r.x();
      out[1] = r.y();
      out[2] = r.z();
    }
    return true;
  }
};

TEST(ScanMatcher, GaussNewtonAgreesWithCeresOnTheSameCorrespondences) {
  LidarOdometry odom{LidarOdometryConfig{}};
  Eigen::Isometry3d truth;
  prepare("street_night", 30, 34, odom, truth);
  ScanMatcherConfig mc;
  mc.max_iterations = 1;
  ScanMatcher matcher(mc);
  const Eigen::Isometry3d start = retract(truth, offset(1.0, 0.15));
  matcher.match(odom.features().edges, odom.features().planes, odom.edge_map(), odom.plane_map(),
                start);
  const std::vector<Correspondence> fixed = matcher.correspondences();
  ASSERT_GT(fixed.size(), 500u);

  // Eigen: Gauss-Newton on the fixed correspondences until it stops moving.
  Eigen::Isometry3d T = start;
  for (int it = 0; it < 50; ++it) {
    Eigen::Matrix<double, 6, 6> H;
    Eigen::Matrix<double, 6, 1> g;
    normal_equations(fixed, T, mc.cauchy_scale_m, H, g);
    const Eigen::Matrix<double, 6, 1> d = -H.ldlt().solve(g);
    T = retract(T, d);
    if (d.norm() < 1e-10) break;
  }
  // Ceres: the same cost (Cauchy with the same scale) on a quaternion + translation.
  Eigen::Quaterniond q(start.linear());
  Eigen::Vector3d t = start.translation();
  ceres::Problem problem;
  for (const Correspondence& c : fixed) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PointResidual, 3, 4, 3>(new PointResidual{c}),
        new ceres::CauchyLoss(mc.cauchy_scale_m), q.coeffs().data(), t.data());
  }
  problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  options.max_num_iterations = 200;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  EXPECT_LT((t - T.translation()).norm(), 1e-5);
  EXPECT_LT(q.angularDistance(Eigen::Quaterniond(T.linear())), 1e-6);
}

Degeneracy degeneracy_at_truth(const std::string& scenario, std::size_t scan,
                               Eigen::Isometry3d& truth) {
  LidarOdometry odom{LidarOdometryConfig{}};
  prepare(scenario, scan, scan + 1, odom, truth);
  ScanMatcherConfig mc;
  mc.max_iterations = 1;
  ScanMatcher matcher(mc);
  matcher.match(odom.features().edges, odom.features().planes, odom.edge_map(), odom.plane_map(),
                truth);
  Eigen::Matrix<double, 6, 6> H;
  Eigen::Matrix<double, 6, 1> g;
  normal_equations(matcher.correspondences(), truth, mc.cauchy_scale_m, H, g);
  return analyse_degeneracy(H, mc);
}

TEST(ScanMatcher, DegeneracyIsFoundAlongACorridorAndNotInAStreet) {
  const sim::LidarImuRun& corridor = test::simulated("corridor", 6.0);
  int corridor_degenerate = 0;
  for (const std::size_t scan : {30u, 40u, 50u}) {
    Eigen::Isometry3d truth;
    const Degeneracy d = degeneracy_at_truth("corridor", scan, truth);
    EXPECT_GE(d.degenerate_directions, 1) << "corridor scan " << scan;
    // The weakest translation direction is the corridor's axis: along the vehicle's heading.
    const Eigen::Vector3d weakest_lidar = d.eigenvectors.block<3, 1>(3, 3);
    const Eigen::Vector3d heading_lidar =
        truth.linear().transpose() *
        (corridor.T_map_lidar(corridor.scans.at(scan + 1).end).translation() -
         corridor.T_map_lidar(corridor.scans.at(scan).end).translation())
            .normalized();
    EXPECT_GT(std::abs(weakest_lidar.dot(heading_lidar)), 0.9) << "corridor scan " << scan;
    corridor_degenerate += d.keep(3) == 0.0 ? 1 : 0;
  }
  EXPECT_EQ(corridor_degenerate, 3);
  for (const std::size_t scan : {30u, 40u, 50u}) {
    Eigen::Isometry3d truth;
    const Degeneracy d = degeneracy_at_truth("street_night", scan, truth);
    EXPECT_EQ(d.degenerate_directions, 0) << "street scan " << scan;
    EXPECT_GT(d.eigenvalues(3), 5 * ScanMatcherConfig{}.degeneracy_translation_threshold);
  }
}

TEST(ScanMatcher, DegenerateDirectionsKeepThePrediction) {
  LidarOdometry odom{LidarOdometryConfig{}};
  Eigen::Isometry3d truth;
  prepare("corridor", 40, 41, odom, truth);
  ScanMatcherConfig mc;
  ScanMatcher matcher(mc);
  matcher.match(odom.features().edges, odom.features().planes, odom.edge_map(), odom.plane_map(),
                truth);
  Eigen::Matrix<double, 6, 6> H;
  Eigen::Matrix<double, 6, 1> g;
  normal_equations(matcher.correspondences(), truth, mc.cauchy_scale_m, H, g);
  const Degeneracy at_truth = analyse_degeneracy(H, mc);
  ASSERT_EQ(at_truth.keep(3), 0.0) << "the corridor's axis is not degenerate here";
  const Eigen::Vector3d axis = at_truth.eigenvectors.block<3, 1>(3, 3);
  // Offset purely along the axis: the remapped solve leaves it alone and gives no information
  // along it; without remapping the solve moves along it freely.
  Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
  d.tail<3>() = 0.4 * axis;
  const Eigen::Isometry3d guess = retract(truth, d);
  const ScanMatchResult r = matcher.match(odom.features().edges, odom.features().planes,
                                          odom.edge_map(), odom.plane_map(), guess);
  ASSERT_TRUE(r.ok);
  ASSERT_GE(r.degenerate_directions, 1);
  const Eigen::Vector3d moved =
      guess.linear().transpose() * (r.T_map_lidar.translation() - guess.translation());
  EXPECT_LT(std::abs(moved.dot(axis)), 0.03);
  Eigen::Matrix<double, 6, 1> along = Eigen::Matrix<double, 6, 1>::Zero();
  along.tail<3>() = axis;
  EXPECT_LT(along.dot(r.information * along), 1e-3 * r.information.trace());
}

}  // namespace
}  // namespace posed::lidar

namespace posed::lidar {
namespace {

/// Runs the parts last first: work cut by the core must not depend on the order parts run in.
class ReversedSplitter final : public WorkSplitter {
 public:
  void run(std::size_t parts, const Part& part) override {
    for (std::size_t i = parts; i-- > 0;) part(i);
    ++jobs;
  }
  int jobs = 0;
};

TEST(ScanMatcher, FeaturesAndMatchAreTheSameWhateverOrderTheirPartsRunIn) {
  for (const std::string scenario : {"street_night", "corridor"}) {
    LidarOdometry plain{LidarOdometryConfig{}}, split{LidarOdometryConfig{}};
    ReversedSplitter splitter;
    split.set_splitter(&splitter);
    Eigen::Isometry3d truth;
    prepare(scenario, 30, 33, plain, truth);
    prepare(scenario, 30, 33, split, truth);
    EXPECT_GT(splitter.jobs, 0) << "the splitter was never asked";
    ASSERT_EQ(plain.features().edges, split.features().edges) << scenario;
    ASSERT_EQ(plain.features().planes, split.features().planes) << scenario;
    const Eigen::Isometry3d guess = retract(truth, offset(1.0, 0.2));
    const ScanMatchResult a = plain.match(guess);
    const ScanMatchResult b = split.match(guess);
    ASSERT_TRUE(a.ok) << scenario;
    EXPECT_EQ(a.T_map_lidar.matrix(), b.T_map_lidar.matrix()) << scenario;
    EXPECT_EQ(a.information, b.information) << scenario;
    EXPECT_EQ(a.plane_correspondences, b.plane_correspondences) << scenario;
    EXPECT_EQ(a.edge_correspondences, b.edge_correspondences) << scenario;
  }
}

}  // namespace
}  // namespace posed::lidar
