#include "core/mapping/loop_closer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tests/unit/mapping/deskewed_scan.hpp"
#include "tests/unit/mapping/synthetic_scene.hpp"

namespace posed::mapping {
namespace {

/// Odometry that drifts as lidar odometry does where geometry is poor: a heading error growing
/// by `yaw_radps` and a position error by `drift_mps` along the start's x, from the first pose
/// (or only between `degenerate_from_s` and `degenerate_to_s` when those are set: a stretch
/// where the matching was degenerate).
struct DriftingOdometry {
  double yaw_radps = 0.0;
  double drift_mps = 0.0;
  double degenerate_from_s = 0.0;
  double degenerate_to_s = 1e9;
  double seconds(const sim::LidarImuRun& run, HostTime t) const {
    return static_cast<double>(t.ns - run.scans.front().end.ns) * 1e-9;
  }
  bool degenerate(const sim::LidarImuRun& run, HostTime t) const {
    const double s = seconds(run, t);
    return s >= degenerate_from_s && s < degenerate_to_s;
  }
  Eigen::Isometry3d T_odom_base(const sim::LidarImuRun& run, HostTime t) const {
    const double s =
        std::clamp(seconds(run, t), degenerate_from_s, degenerate_to_s) - degenerate_from_s;
    const Eigen::Isometry3d T_map_start = run.T_map_base(run.scans.front().end);
    // The drift acts about the start pose, so the odometry starts where the truth does.
    const Eigen::Isometry3d D =
        T_map_start * test::pose(drift_mps * s, 0, 0, yaw_radps * s) * T_map_start.inverse();
    return D * run.T_map_base(t);
  }
};

struct Replayed {
  double odometry_error_m = 0;            ///< of the last pose [m]
  double corrected_error_m = 0;           ///< with the loop closer's map -> odom [m]
  double worst_corrected_keyframe_m = 0;  ///< of the keyframes after optimisation [m]
  double rms_corrected_keyframe_m = 0;    ///< of the keyframes after optimisation [m]
  double rms_odometry_keyframe_m = 0;     ///< of the keyframes' odometry poses [m]
};

/// Feeds every scan of `run`, deskewed with the true motion and put in base_link, to `closer`
/// with `odometry`'s poses; `tell_degenerate`: with the share of degenerate scans since the last
/// keyframe, as the daemon does.
Replayed replay(const sim::LidarImuRun& run, const DriftingOdometry& odometry, LoopCloser& closer,
                bool tell_degenerate = false) {
  std::vector<Eigen::Vector3f> points_base;
  int scans = 0, degenerate = 0;
  for (const sim::DecodedScan& scan : run.scans) {
    test::deskewed_base(run, scan, points_base);
    ++scans;
    degenerate += odometry.degenerate(run, scan.end) ? 1 : 0;
    const double share = tell_degenerate ? static_cast<double>(degenerate) / scans : 0.0;
    if (closer.add(scan.end, odometry.T_odom_base(run, scan.end), points_base, share)) {
      scans = degenerate = 0;
    }
  }
  Replayed out;
  const HostTime end = run.scans.back().end;
  const Eigen::Vector3d truth = run.T_map_base(end).translation();
  // The graph's map frame is the first keyframe's odometry frame, which the drift leaves
  // where the truth's map frame is.
  out.odometry_error_m = (odometry.T_odom_base(run, end).translation() - truth).norm();
  out.corrected_error_m =
      ((closer.T_map_odom() * odometry.T_odom_base(run, end)).translation() - truth).norm();
  double sum2 = 0, odometry_sum2 = 0;
  for (std::size_t i = 0; i < closer.keyframe_count(); ++i) {
    const HostTime stamp = closer.keyframe_stamp(i);
    const Eigen::Vector3d kf_truth = run.T_map_base(stamp).translation();
    const double e = (closer.T_map_keyframe(i).translation() - kf_truth).norm();
    out.worst_corrected_keyframe_m = std::max(out.worst_corrected_keyframe_m, e);
    sum2 += e * e;
    odometry_sum2 += (odometry.T_odom_base(run, stamp).translation() - kf_truth).squaredNorm();
  }
  const auto n = static_cast<double>(std::max<std::size_t>(1, closer.keyframe_count()));
  out.rms_corrected_keyframe_m = std::sqrt(sum2 / n);
  out.rms_odometry_keyframe_m = std::sqrt(odometry_sum2 / n);
  return out;
}

/// The room's loop closer for odometry that drifts by DriftingOdometry's exaggerated rates (14 deg
/// a minute), so that each correction is plain to see. The odometry edges' model (0.001 rad/m)
/// rules such a drift out, and the plausibility test would refuse its loops: it is off here and
/// tested on its own (RefusesALookAlikePlace...).
LoopClosureConfig room_config_for_exaggerated_drift() {
  LoopClosureConfig config;
  config.min_separation_s = 15.0;
  config.loop_max_correction_sigmas = 0.0;
  return config;
}

TEST(LoopCloser, ClosesTheRoomsLoopAndTakesOutTheDrift) {
  const sim::LidarImuRun& run = test::simulated("room", 60.0);
  LoopClosureConfig config = room_config_for_exaggerated_drift();
  LoopCloser closer(config);
  const DriftingOdometry odometry{.yaw_radps = 0.004, .drift_mps = 0.02};
  const Replayed r = replay(run, odometry, closer);
  const LoopClosureFigures& f = closer.figures();
  EXPECT_GT(f.keyframes, 20u);
  ASSERT_GT(f.loops, 0u) << "attempts " << f.attempts << " candidates " << f.distance_candidates
                         << "/" << f.descriptor_candidates << " rejected diverged " << f.rejected[2]
                         << " not_close " << f.rejected[3] << " low_overlap " << f.rejected[4]
                         << " degenerate " << f.rejected[5];
  for (const LoopRecord& loop : closer.loops()) {
    EXPECT_LT(loop.rms_m, config.registration.max_rms_m);
    EXPECT_GE(loop.overlap, config.registration.min_overlap);
  }
  // The loops pull the keyframes back onto the truth (measured: 0.14 m RMS against the
  // odometry's 0.49 m, 3 loops); the newest pose keeps what the odometry drifted since the last
  // loop (none is looked for over cooldown_keyframes after one).
  EXPECT_GT(r.odometry_error_m, 0.4);
  EXPECT_LT(r.rms_corrected_keyframe_m, 0.4 * r.rms_odometry_keyframe_m)
      << "worst " << r.worst_corrected_keyframe_m;
  EXPECT_LT(r.corrected_error_m, 0.4 * r.odometry_error_m);
}

TEST(LoopCloser, PutsTheCorrectionWhereTheOdometryWasDegenerate) {
  // The odometry drifts only over 8-16 s, where its matching was degenerate; told so, the graph
  // puts the loops' correction there instead of spreading it over the whole lap.
  const sim::LidarImuRun& run = test::simulated("room", 60.0);
  LoopClosureConfig config;
  config.min_separation_s = 15.0;
  config.odometry_sigma_translation_degenerate_per_m = 0.5;
  config.odometry_sigma_rotation_degenerate_per_m = 0.05;
  const DriftingOdometry odometry{
      .yaw_radps = 0.02, .drift_mps = 0.08, .degenerate_from_s = 8, .degenerate_to_s = 16};
  LoopCloser uniform(config);
  const Replayed u = replay(run, odometry, uniform, false);
  LoopCloser weighted(config);
  const Replayed w = replay(run, odometry, weighted, true);
  ASSERT_GT(uniform.figures().loops, 0u);
  ASSERT_GT(weighted.figures().loops, 0u);
  std::printf(
      "keyframe RMS: odometry %.3f m, loops %.3f m, loops told the degenerate stretch "
      "%.3f m\n",
      u.rms_odometry_keyframe_m, u.rms_corrected_keyframe_m, w.rms_corrected_keyframe_m);
  EXPECT_LT(w.rms_corrected_keyframe_m, 0.7 * u.rms_corrected_keyframe_m);
}

TEST(LoopCloser, FindsLoopsByDescriptorAloneWhenTheEstimateIsNoGuide) {
  const sim::LidarImuRun& run = test::simulated("room", 60.0);
  LoopClosureConfig config = room_config_for_exaggerated_drift();
  // No candidate is ever near enough the estimate: only Scan Context can find the revisits, and
  // each of its loops must be confirmed by the next attempt before it is accepted.
  config.search_radius_m = 0.0;
  LoopCloser closer(config);
  const DriftingOdometry odometry{.yaw_radps = 0.004, .drift_mps = 0.02};
  const Replayed r = replay(run, odometry, closer);
  ASSERT_FALSE(closer.loops().empty());
  for (const LoopRecord& loop : closer.loops()) {
    EXPECT_TRUE(loop.by_descriptor);
  }
  EXPECT_GT(r.odometry_error_m, 0.4);
  EXPECT_LT(r.rms_corrected_keyframe_m, 0.4 * r.rms_odometry_keyframe_m)
      << "worst " << r.worst_corrected_keyframe_m;
  EXPECT_LT(r.corrected_error_m, 0.4 * r.odometry_error_m);
}

TEST(LoopCloser, KeyframesInAMappedPlaceKeepNoCloudAndTheLoopsStillHold) {
  // Three laps of the room: after the first loop, a keyframe near an older one that keeps its
  // cloud drops its own, so laps after the first add poses, not points.
  const sim::LidarImuRun& run = test::simulated("room", 60.0);
  const DriftingOdometry odometry{.yaw_radps = 0.004, .drift_mps = 0.02};
  LoopClosureConfig config = room_config_for_exaggerated_drift();
  LoopClosureConfig keep_all = config;
  keep_all.mapped_keyframe_distance_m = 0.0;
  LoopCloser pruned(config);
  const Replayed p = replay(run, odometry, pruned);
  LoopCloser every(keep_all);
  const Replayed e = replay(run, odometry, every);
  const LoopClosureFigures& fp = pruned.figures();
  const LoopClosureFigures& fe = every.figures();
  std::printf(
      "keyframes %llu, %llu without a cloud; points %zu (every cloud kept: %zu); loops %llu (%llu);"
      " keyframe RMS %.3f m (%.3f m)\n",
      static_cast<unsigned long long>(fp.keyframes),
      static_cast<unsigned long long>(fp.mapped_keyframes), fp.stored_points, fe.stored_points,
      static_cast<unsigned long long>(fp.loops), static_cast<unsigned long long>(fe.loops),
      p.rms_corrected_keyframe_m, e.rms_corrected_keyframe_m);
  EXPECT_EQ(fe.mapped_keyframes, 0u);
  ASSERT_GT(fp.loops, 0u);
  EXPECT_GT(fp.mapped_keyframes, fp.keyframes / 4);
  EXPECT_LT(fp.stored_points, 0.8 * static_cast<double>(fe.stored_points));

  // The figures count what the keyframes hold, and every keyframe without a cloud has an older
  // one with a cloud where the graph puts it (the optimisations since may have moved both a bit).
  std::size_t held = 0, held_bytes = 0;
  for (std::size_t i = 0; i < pruned.keyframe_count(); ++i) {
    held += pruned.keyframe_points(i).size();
    held_bytes += pruned.keyframe_points(i).bytes();
    if (pruned.keyframe_points(i).size() > 0) continue;
    double nearest_m = 1e9;
    for (std::size_t j = 0; j < i; ++j) {
      if (pruned.keyframe_points(j).size() == 0) continue;
      nearest_m = std::min(
          nearest_m,
          (pruned.T_map_keyframe(j).translation() - pruned.T_map_keyframe(i).translation()).norm());
    }
    EXPECT_LT(nearest_m, config.mapped_keyframe_distance_m + 0.3) << "keyframe " << i;
  }
  EXPECT_EQ(held, fp.stored_points);
  EXPECT_EQ(held_bytes, fp.stored_bytes);
  // A keyframe without a cloud has no descriptor either; one with a cloud keeps its descriptor.
  const KeyframeMap map = pruned.snapshot();
  for (std::size_t i = 0; i < map.keyframes.size(); ++i) {
    EXPECT_EQ(map.keyframes[i].points_base.size() == 0, map.keyframes[i].context.bins.size() == 0)
        << "keyframe " << i;
  }

  // Loops found onto the older clouds take the drift out as well as with every cloud kept.
  EXPECT_LT(p.rms_corrected_keyframe_m, 0.4 * p.rms_odometry_keyframe_m);
  EXPECT_LT(p.rms_corrected_keyframe_m, 1.25 * e.rms_corrected_keyframe_m + 0.02);
  EXPECT_LT(p.corrected_error_m, 0.4 * p.odometry_error_m);
}

TEST(LoopCloser, NoKeyframeDropsItsCloudBeforeALoopVouchesForTheMap) {
  // The same laps with every loop refused (no registration fits that well): a drifting
  // estimate's "near an older keyframe" means nothing, so every cloud stays.
  const sim::LidarImuRun& run = test::simulated("room", 60.0);
  LoopClosureConfig config;
  config.min_separation_s = 15.0;
  config.registration.max_rms_m = 1e-6;
  LoopCloser closer(config);
  replay(run, DriftingOdometry{.yaw_radps = 0.004, .drift_mps = 0.02}, closer);
  EXPECT_GT(closer.figures().distance_candidates, 5u);
  EXPECT_EQ(closer.figures().loops, 0u);
  EXPECT_EQ(closer.figures().mapped_keyframes, 0u);
  for (std::size_t i = 0; i < closer.keyframe_count(); ++i) {
    EXPECT_GT(closer.keyframe_points(i).size(), 0u) << "keyframe " << i;
  }
}

/// Two laps of the room, then the same scans again in a twin room 60 m away and turned by 40
/// deg (the drive between them is one odometry edge): every keyframe of the twin matches one of
/// the first room by descriptor and registers onto it as well as onto its own, and only the
/// odometry says the places differ. Returns the loops from the twin onto the first room.
std::size_t loops_into_a_twin_room(LoopCloser& closer) {
  const sim::LidarImuRun& run = test::simulated("room", 60.0);
  const Eigen::Isometry3d T_twin = test::pose(60, 0, 0, 40.0 * M_PI / 180.0);
  const std::int64_t pass_ns = run.scans.back().end.ns - run.scans.front().end.ns + 1'000'000'000;
  const HostTime twin_from{run.scans.front().end.ns + pass_ns};
  std::vector<Eigen::Vector3f> points_base;
  for (int pass = 0; pass < 2; ++pass) {
    for (const sim::DecodedScan& scan : run.scans) {
      test::deskewed_base(run, scan, points_base);
      const Eigen::Isometry3d T_odom_base =
          pass == 0 ? run.T_map_base(scan.end) : T_twin * run.T_map_base(scan.end);
      closer.add(HostTime{scan.end.ns + pass * pass_ns}, T_odom_base, points_base);
    }
  }
  std::size_t across = 0;
  for (const LoopRecord& loop : closer.loops()) {
    across += closer.keyframe_stamp(loop.query) >= twin_from &&
              closer.keyframe_stamp(loop.candidate) < twin_from;
  }
  return across;
}

TEST(LoopCloser, RefusesALookAlikePlaceWhoseCorrectionTheOdometryCannotHaveDrifted) {
  LoopClosureConfig config;
  config.min_separation_s = 15.0;
  // Without the test the twin's descriptor matches are confirmed and accepted: the scene does
  // fool the registration.
  config.loop_max_correction_sigmas = 0.0;
  LoopCloser fooled(config);
  ASSERT_GT(loops_into_a_twin_room(fooled), 0u);
  ASSERT_GT(fooled.T_map_odom().translation().norm(), 30.0);

  config.loop_max_correction_sigmas = LoopClosureConfig{}.loop_max_correction_sigmas;
  LoopCloser closer(config);
  EXPECT_EQ(loops_into_a_twin_room(closer), 0u);
  const LoopClosureFigures& f = closer.figures();
  EXPECT_GT(f.implausible, 0u);
  ASSERT_TRUE(closer.last_implausible().has_value());
  EXPECT_GT(closer.last_implausible()->correction_m, 30.0);
  std::printf(
      "fooled: %zu loops, map -> odom %.1f m; tested: %llu loops, %llu implausible (last "
      "%.1f m, %.1f sigma)\n",
      fooled.loops().size(), fooled.T_map_odom().translation().norm(),
      static_cast<unsigned long long>(f.loops), static_cast<unsigned long long>(f.implausible),
      closer.last_implausible()->correction_m, closer.last_implausible()->correction_sigmas);
  // Each room's own revisits still close, each well within the odometry's reach.
  ASSERT_GT(f.loops, 1u);
  for (const LoopRecord& loop : closer.loops()) EXPECT_LT(loop.correction_sigmas, 3.0);
  EXPECT_LT(closer.T_map_odom().translation().norm(), 0.5);
}

TEST(LoopCloser, KeyframeCloudsKeepThePointsWithinTheirRangeAndTheMapSaysHowFar) {
  // A wall 90 m ahead beyond a floor near the sensor: kept with a 120 m reach, dropped with 60 m.
  std::vector<Eigen::Vector3f> points_base;
  for (float y = -10; y <= 10; y += 0.25f) {
    for (float z = 0; z <= 6; z += 0.25f) points_base.emplace_back(90.0f, y, z);
  }
  for (float x = -20; x <= 20; x += 0.25f) {
    for (float y = -20; y <= 20; y += 0.25f) points_base.emplace_back(x, y, -1.5f);
  }
  for (const double range_m : {60.0, 120.0}) {
    LoopClosureConfig config;
    config.keyframe_max_range_m = range_m;
    LoopCloser closer(config);
    closer.add_keyframe(HostTime{1'000'000'000}, Eigen::Isometry3d::Identity(), points_base);
    const KeyframeMap map = closer.snapshot();
    ASSERT_EQ(map.keyframes.size(), 1u);
    EXPECT_DOUBLE_EQ(map.max_range_m, range_m);
    int far = 0;
    for (const Eigen::Vector3f& p : map.keyframes[0].points_base) far += p.x() > 80.0f ? 1 : 0;
    if (range_m > 90.0) {
      EXPECT_GT(far, 500) << "the wall is kept";
    } else {
      EXPECT_EQ(far, 0) << "the wall is beyond reach";
    }
  }
}

TEST(LoopCloser, WithoutLoopsTheCorrectionStaysIdentity) {
  const sim::LidarImuRun& run = test::simulated("room", 60.0);
  LoopClosureConfig config;
  config.min_separation_s = 1000.0;  // nothing is ever old enough to be a loop
  LoopCloser closer(config);
  const Replayed r = replay(run, DriftingOdometry{.yaw_radps = 0.002, .drift_mps = 0.01}, closer);
  EXPECT_EQ(closer.figures().loops, 0u);
  EXPECT_TRUE(closer.T_map_odom().isApprox(Eigen::Isometry3d::Identity(), 1e-9));
  EXPECT_NEAR(r.corrected_error_m, r.odometry_error_m, 1e-9);
}

TEST(LoopCloser, AcceptsNoLoopInAPlainCorridorWhereOdometrySlidAlongIt) {
  // Odometry that slid along the corridor: every revisit's registration could only agree with
  // the wrong estimate. None may be accepted.
  const sim::LidarImuRun& run = test::simulated("corridor", 60.0);
  LoopClosureConfig config;
  config.min_separation_s = 20.0;
  LoopCloser closer(config);
  replay(run, DriftingOdometry{.yaw_radps = 0.0, .drift_mps = 0.05}, closer);
  const LoopClosureFigures& f = closer.figures();
  EXPECT_GT(f.distance_candidates + f.descriptor_candidates, 5u);
  EXPECT_EQ(f.loops, 0u) << "first loop: keyframe " << closer.loops().front().query << " -> "
                         << closer.loops().front().candidate << " constraint "
                         << closer.loops().front().constraint;
}

}  // namespace
}  // namespace posed::mapping
