#include "core/mapping/localiser.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/mapping/loop_closer.hpp"
#include "tests/unit/mapping/deskewed_scan.hpp"
#include "tests/unit/mapping/synthetic_scene.hpp"

namespace posed::mapping {
namespace {

constexpr double kMapSeconds = 20.0;  ///< the room's first 20 s (a lap) make the map
constexpr double kRunSeconds = 36.0;  ///< simulated

/// The map a mapping run with exact odometry builds from the room's first kMapSeconds: its map
/// frame is the simulator's.
KeyframeMap room_map(const sim::LidarImuRun& run) {
  LoopClosureConfig config;
  config.min_separation_s = 1e9;  // keyframes only
  LoopCloser closer(config);
  std::vector<Eigen::Vector3f> points_base;
  for (const sim::DecodedScan& scan : run.scans) {
    if (static_cast<double>(scan.end.ns - run.scans.front().end.ns) * 1e-9 > kMapSeconds) {
      break;
    }
    test::deskewed_base(run, scan, points_base);
    closer.add(scan.end, run.T_map_base(scan.end), points_base);
  }
  return closer.snapshot();
}

struct Localised {
  std::optional<double> seconds_to_fix;  ///< of data from the first scan [s]
  double worst_error_m = 0;              ///< of the map-frame pose at every scan once localised [m]
  std::size_t scans_localised = 0;
};

/// Scans from `start_s` to `end_s` of the run, with odometry whose frame is `T_truth_odom` off the
/// map (the robot booted somewhere else), through `localiser`.
Localised localise(const sim::LidarImuRun& run, Localiser& localiser,
                   const Eigen::Isometry3d& T_truth_odom, double start_s, double end_s) {
  Localised out;
  std::vector<Eigen::Vector3f> points_base;
  std::optional<HostTime> first;
  for (const sim::DecodedScan& scan : run.scans) {
    const double t = static_cast<double>(scan.end.ns - run.scans.front().end.ns) * 1e-9;
    if (t < start_s || t > end_s) {
      continue;
    }
    if (!first) {
      first = scan.end;
    }
    test::deskewed_base(run, scan, points_base);
    const Eigen::Isometry3d T_odom_base = T_truth_odom.inverse() * run.T_map_base(scan.end);
    localiser.add_scan(scan.end, T_odom_base, points_base);
    if (localiser.state() != LocalisationState::kLocalised) {
      continue;
    }
    if (!out.seconds_to_fix) {
      out.seconds_to_fix = static_cast<double>(scan.end.ns - first->ns) * 1e-9;
    }
    ++out.scans_localised;
    const Eigen::Vector3d estimate = (localiser.T_map_odom() * T_odom_base).translation();
    out.worst_error_m =
        std::max(out.worst_error_m, (estimate - run.T_map_base(scan.end).translation()).norm());
  }
  return out;
}

TEST(Localiser, RelocalisesByDescriptorWithinTwoSecondsAndTracksTheMap) {
  const sim::LidarImuRun& run = test::simulated("room", kRunSeconds);
  Localiser localiser(room_map(run), LocalisationConfig{});
  EXPECT_EQ(localiser.state(), LocalisationState::kAligning);
  // Booted 24 s in, its odometry frame 7 m and 100 degrees away from the map's.
  const Localised r = localise(run, localiser, test::pose(5, -5, 0.3, 1.75), 24.0, kRunSeconds);
  const LocalisationFigures& f = localiser.figures();
  ASSERT_TRUE(r.seconds_to_fix) << "lookups " << f.lookups << " unconfirmed " << f.unconfirmed
                                << " rejected: not_close " << f.rejected[3] << " low_overlap "
                                << f.rejected[4] << " degenerate " << f.rejected[5];
  std::printf("relocalised after %.2f s of data; worst error %.3f m over %zu scans, %llu fixes\n",
              *r.seconds_to_fix, r.worst_error_m, r.scans_localised,
              static_cast<unsigned long long>(f.fixes));
  EXPECT_LE(*r.seconds_to_fix, 2.0);
  EXPECT_EQ(localiser.state(), LocalisationState::kLocalised);
  EXPECT_GT(f.fixes, 3u);  // tracked, not one lucky fix
  EXPECT_LT(r.worst_error_m, 0.10) << "over " << r.scans_localised << " scans";
}

TEST(Localiser, RelocalisesOnAMapWhoseRevisitsKeptNoClouds) {
  // The map a mapping run makes over the whole run, loops closed: the second lap's keyframes
  // left their clouds to the first lap's (LoopClosureConfig::mapped_keyframe_distance_m), and a
  // descriptor match onto one of them must still find clouds to register onto.
  const sim::LidarImuRun& run = test::simulated("room", kRunSeconds);
  LoopClosureConfig config;
  config.min_separation_s = 15.0;
  LoopCloser closer(config);
  std::vector<Eigen::Vector3f> points_base;
  for (const sim::DecodedScan& scan : run.scans) {
    test::deskewed_base(run, scan, points_base);
    closer.add(scan.end, run.T_map_base(scan.end), points_base);
  }
  ASSERT_GT(closer.figures().mapped_keyframes, 5u);
  // Two keyframes a registration: the nearest to the robot are often the second lap's, and it
  // must register onto the nearest that have clouds.
  LocalisationConfig localisation;
  localisation.track_keyframes = 2;
  Localiser localiser(closer.snapshot(), localisation);
  const Localised r = localise(run, localiser, test::pose(5, -5, 0.3, 1.75), 24.0, kRunSeconds);
  ASSERT_TRUE(r.seconds_to_fix) << "lookups " << localiser.figures().lookups;
  EXPECT_LE(*r.seconds_to_fix, 2.0);
  EXPECT_GT(localiser.figures().fixes, 3u);
  EXPECT_LT(r.worst_error_m, 0.10) << "over " << r.scans_localised << " scans";
}

TEST(Localiser, AnInitialPoseLocalisesAtTheFirstScan) {
  const sim::LidarImuRun& run = test::simulated("room", kRunSeconds);
  Localiser localiser(room_map(run), LocalisationConfig{});
  const double start_s = 30.0;
  const HostTime at =
      run.scans.front().end + Duration::from_ns(static_cast<std::int64_t>(start_s * 1e9));
  // What a user clicks in RViz: half a metre and 6 degrees off the truth.
  localiser.set_initial_pose(run.T_map_base(at) * test::pose(0.4, -0.3, 0, 0.1));
  const Localised r = localise(run, localiser, test::pose(-20, 3, 0, -2.0), start_s, 34.0);
  ASSERT_TRUE(r.seconds_to_fix);
  EXPECT_LT(*r.seconds_to_fix, 0.15);  // the first or second scan
  EXPECT_LT(r.worst_error_m, 0.10);
}

TEST(Localiser, AFirstFixMustPinEveryDirectionAsMuchAsAsked) {
  // The room pins every direction well (~0.2 per point): a first fix that must reach 0.05 is
  // taken at once; one that must reach 0.9 never is, though each registration verifies.
  const sim::LidarImuRun& run = test::simulated("room", kRunSeconds);
  const double start_s = 30.0;
  const HostTime at =
      run.scans.front().end + Duration::from_ns(static_cast<std::int64_t>(start_s * 1e9));
  for (const double min_constraint : {0.05, 0.9}) {
    LocalisationConfig config;
    config.first_fix_min_constraint = min_constraint;
    Localiser localiser(room_map(run), config);
    localiser.set_initial_pose(run.T_map_base(at) * test::pose(0.4, -0.3, 0, 0.1));
    const Localised r = localise(run, localiser, test::pose(-20, 3, 0, -2.0), start_s, 31.0);
    const std::uint64_t degenerate =
        localiser.figures().rejected[static_cast<std::size_t>(RegistrationVerdict::kDegenerate)];
    if (min_constraint < 0.1) {
      ASSERT_TRUE(r.seconds_to_fix);
      EXPECT_LT(r.worst_error_m, 0.10);
    } else {
      EXPECT_FALSE(r.seconds_to_fix);
      EXPECT_EQ(localiser.figures().fixes, 0u);
      EXPECT_GT(degenerate, 5u);
    }
  }
}

TEST(Localiser, StaysAligningOffTheMap) {
  // A map of the room, a robot in the corridor: nothing may be taken for a fix.
  const sim::LidarImuRun& room = test::simulated("room", kRunSeconds);
  const sim::LidarImuRun& corridor = test::simulated("corridor", 5.0);
  Localiser localiser(room_map(room), LocalisationConfig{});
  const Localised r = localise(corridor, localiser, Eigen::Isometry3d::Identity(), 0.0, 4.0);
  EXPECT_FALSE(r.seconds_to_fix);
  EXPECT_EQ(localiser.figures().fixes, 0u);
  EXPECT_GT(localiser.figures().lookups, 30u);
}

}  // namespace
}  // namespace posed::mapping
