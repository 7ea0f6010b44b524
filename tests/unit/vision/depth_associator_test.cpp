// Lidar depth for features (seed 000 §2.2.1): exact depths on known planes, rejection when the
// 3 neighbours straddle a depth edge (span > 2 m), the two span definitions, and the other
// guards (no points, neighbours too far, collinear neighbours, hidden points).

#include "core/vision/depth_associator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "tests/unit/vision/synthetic_scene.hpp"

namespace posed::vision {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

/// A lidar-like sweep in the camera frame: `rings` elevations evenly over [-25, 15] deg (up is
/// -y), azimuth every `step_deg` over +-60 deg, each ray ending where `range_of` says (<= 0:
/// no return).
std::vector<Eigen::Vector3f> sweep(const std::function<double(const Eigen::Vector3d&)>& range_of,
                                   int rings = 32, double step_deg = 0.2) {
  std::vector<Eigen::Vector3f> points;
  for (int ring = 0; ring < rings; ++ring) {
    const double elevation = (-25.0 + 40.0 * ring / (rings - 1)) * kDeg;
    for (double az = -60; az <= 60; az += step_deg) {
      const Eigen::Vector3d d(std::cos(elevation) * std::sin(az * kDeg), -std::sin(elevation),
                              std::cos(elevation) * std::cos(az * kDeg));
      const double r = range_of(d);
      if (r > 0) points.push_back((r * d).cast<float>());
    }
  }
  return points;
}

/// Range along unit direction d to the plane z = z0 + slope_x x.
double plane_range(const Eigen::Vector3d& d, double z0, double slope_x) {
  const double denominator = d.z() - slope_x * d.x();
  return denominator > 1e-9 ? z0 / denominator : -1;
}

TEST(DepthAssociator, RecoversTheDepthOfATiltedPlane) {
  DepthAssociator depth({}, scene::m2dgr_visible());
  const auto cloud = sweep([](const Eigen::Vector3d& d) { return plane_range(d, 8.0, 0.3); });
  depth.set_points(cloud);
  EXPECT_GT(depth.tree_points(), 1000u);
  EXPECT_LT(depth.tree_points(), cloud.size());  // culled to the image's field of view
  cv::RNG rng(4);
  int associated = 0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector2d xy(rng.uniform(-0.45, 0.45), rng.uniform(-0.3, 0.3));
    const DepthResult r = depth.depth(xy);
    if (r.status != DepthStatus::kOk) continue;
    ++associated;
    const double expected = 8.0 / (1.0 - 0.3 * xy.x());  // z on the plane along (x, y, 1)
    EXPECT_NEAR(r.depth_m, expected, 1e-4 * expected) << xy.transpose();
  }
  // Rings 1.3 deg apart, 0.2 deg along a ring: the 3 nearest are usually on one ring, and the
  // third point then comes from the next ring.
  EXPECT_GT(associated, 290);
}

TEST(DepthAssociator, RejectsNeighboursStraddlingADepthEdge) {
  // Left of x/z = 0.05 a wall at 5 m, right of it a wall at 12 m.
  DepthAssociator depth({}, scene::m2dgr_visible());
  depth.set_points(sweep([](const Eigen::Vector3d& d) {
    return d.x() / d.z() < 0.05 ? plane_range(d, 5.0, 0) : plane_range(d, 12.0, 0);
  }));
  int edge_rejected = 0, edge_probes = 0;
  for (double y = -0.3; y <= 0.3; y += 0.01) {
    for (double x = -0.4; x <= 0.4; x += 0.01) {
      const DepthResult r = depth.depth({x, y});
      if (r.status == DepthStatus::kOk) {
        // Whatever is associated is one of the walls, never a depth in between; away from the
        // edge (more than the 0.25 deg sampling) it is the wall the feature is on.
        const bool near_wall = std::abs(r.depth_m - 5.0) < 1e-3;
        const bool far_wall = std::abs(r.depth_m - 12.0) < 1e-3;
        EXPECT_TRUE(near_wall || far_wall) << x << "," << y << ": " << r.depth_m;
        if (x < 0.05 - 0.01) {
          EXPECT_TRUE(near_wall) << x << "," << y;
        }
        if (x > 0.05 + 0.01) {
          EXPECT_TRUE(far_wall) << x << "," << y;
        }
      }
      if (std::abs(x - 0.05) < 0.004) {  // within ~0.25 deg of the edge
        ++edge_probes;
        edge_rejected += r.status == DepthStatus::kSpan ? 1 : 0;
      }
    }
  }
  // On the edge the nearest points come from both walls (span ~7 m) and are rejected, unless
  // all three chosen happen to lie on one side; that side's depth is then exact (checked above).
  EXPECT_GT(edge_probes, 40);
  EXPECT_GT(edge_rejected, 0.7 * edge_probes) << edge_rejected << " of " << edge_probes;
}

TEST(DepthAssociator, SpanDefinitions) {
  // A wall 80 m away seen with coarse rings (2.7 deg apart): neighbours on it are ~2-4 m apart
  // although the wall is flat and faces the camera. The paper's span (largest pairwise distance)
  // rejects them; LVI-SAM's range spread accepts them.
  const auto cloud =
      sweep([](const Eigen::Vector3d& d) { return plane_range(d, 80.0, 0); }, 16, 1.5);
  DepthConfig pairwise;
  pairwise.max_neighbour_angle_rad = 4 * kDeg;
  DepthConfig spread = pairwise;
  spread.span = SpanMeasure::kRangeSpread;
  DepthAssociator a(pairwise, scene::m2dgr_visible()), b(spread, scene::m2dgr_visible());
  a.set_points(cloud);
  b.set_points(cloud);
  int a_span = 0, b_ok = 0, probes = 0;
  for (double y = -0.25; y <= 0.25; y += 0.05) {
    for (double x = -0.35; x <= 0.35; x += 0.05) {
      ++probes;
      const DepthResult ra = a.depth({x, y}), rb = b.depth({x, y});
      a_span += ra.status == DepthStatus::kSpan ? 1 : 0;
      if (rb.status == DepthStatus::kOk) {
        ++b_ok;
        EXPECT_NEAR(rb.depth_m, 80.0, 0.01);
        EXPECT_LT(rb.span_m, 2.0);
      }
    }
  }
  EXPECT_EQ(a_span, probes);
  EXPECT_GT(b_ok, probes / 3);
}

TEST(DepthAssociator, NearerSurfaceHidesTheOneBehind) {
  // The same directions return both from 4 m and 30 m (two scans stacked, an object that moved
  // away): the thinning keeps the nearer return per cell.
  auto near_cloud = sweep([](const Eigen::Vector3d& d) { return plane_range(d, 4.0, 0); });
  const auto far_cloud = sweep([](const Eigen::Vector3d& d) { return plane_range(d, 30.0, 0); });
  std::vector<Eigen::Vector3f> stacked = far_cloud;
  stacked.insert(stacked.end(), near_cloud.begin(), near_cloud.end());
  DepthAssociator depth({}, scene::m2dgr_visible());
  depth.set_points(stacked);
  for (double x = -0.3; x <= 0.3; x += 0.1) {
    const DepthResult r = depth.depth({x, 0.013});
    if (r.status == DepthStatus::kOk) {
      EXPECT_NEAR(r.depth_m, 4.0, 1e-3);
    }
  }
}

TEST(DepthAssociator, NoDepthWithoutNearbyPoints) {
  DepthAssociator depth({}, scene::m2dgr_visible());
  // Nothing yet.
  EXPECT_EQ(depth.depth({0, 0}).status, DepthStatus::kNoPoints);
  EXPECT_TRUE(std::isnan(depth.depth({0, 0}).depth_m));
  // Only points behind the camera: culled.
  depth.set_points(sweep([](const Eigen::Vector3d& d) { return d.z() < 0 ? 5.0 : -1.0; }));
  EXPECT_EQ(depth.tree_points(), 0u);
  EXPECT_EQ(depth.depth({0, 0}).status, DepthStatus::kNoPoints);
  // Points only on the right: a feature on the far left is beyond the search radius.
  depth.set_points(sweep([](const Eigen::Vector3d& d) {
    return d.x() / d.z() > 0.2 ? plane_range(d, 6.0, 0) : -1.0;
  }));
  EXPECT_EQ(depth.depth({-0.4, 0}).status, DepthStatus::kTooFar);
}

TEST(DepthAssociator, CollinearNeighboursGiveNoDepth) {
  // One ring only: every neighbour triple is collinear, no plane is defined.
  DepthAssociator depth({}, scene::m2dgr_visible());
  std::vector<Eigen::Vector3f> line;
  for (double az = -30; az <= 30; az += 0.2) {
    line.push_back(Eigen::Vector3f(static_cast<float>(std::sin(az * kDeg) * 7.0), 0.f,
                                   static_cast<float>(std::cos(az * kDeg) * 7.0)));
  }
  depth.set_points(line);
  EXPECT_EQ(depth.depth({0.1, 0.0}).status, DepthStatus::kDegenerate);
}

TEST(DepthAssociator, TheRingSearchFindsExactlyTheNearestKeysABruteForceSearchFinds) {
  DepthAssociator depth({}, scene::m2dgr_visible());
  // Two stacked sweeps of a room-like scene with a gap in it: dense rings, sparse rings, a hole
  // with no returns (the search must walk out of it) and points at the field of view's edges.
  auto cloud = sweep(
      [](const Eigen::Vector3d& d) {
        if (d.x() > 0.1 && d.x() < 0.3) return -1.0;  // no returns: an open door
        return plane_range(d, 6.0, -0.2);
      },
      32, 0.2);
  const auto second =
      sweep([](const Eigen::Vector3d& d) { return plane_range(d, 3.0, 0.5); }, 7, 0.7);
  cloud.insert(cloud.end(), second.begin(), second.end());
  depth.set_points(cloud);
  const std::vector<Eigen::Vector2f>& keys = depth.keys();
  ASSERT_GT(keys.size(), 1000u);

  cv::RNG rng(11);
  std::array<std::uint32_t, 32> index{};
  std::array<float, 32> distance_sq{};
  std::vector<std::pair<float, std::uint32_t>> all;
  int compared = 0, short_of_wanted = 0;
  for (int q = 0; q < 2000; ++q) {
    // Inside and around the field of view (+-40 deg azimuth, +-30 deg elevation and beyond).
    const Eigen::Vector2f key(static_cast<float>(rng.uniform(-0.8, 0.8)),
                              static_cast<float>(rng.uniform(-0.6, 0.6)));
    const std::size_t wanted = static_cast<std::size_t>(rng.uniform(1, 33));
    const double radius =
        q % 3 == 0 ? std::numeric_limits<double>::infinity() : rng.uniform(0.001, 0.08);
    all.clear();
    for (std::uint32_t i = 0; i < keys.size(); ++i) {
      const float dx = key.x() - keys[i].x();
      float d = dx * dx;
      const float dy = key.y() - keys[i].y();
      d += dy * dy;
      if (d <= static_cast<float>(radius * radius)) all.emplace_back(d, i);
    }
    std::sort(all.begin(), all.end());
    const std::size_t expected = std::min(wanted, all.size());
    const std::size_t found = depth.nearest(key, radius, wanted, index.data(), distance_sq.data());
    ASSERT_EQ(found, expected) << "query " << q << " at " << key.transpose();
    for (std::size_t k = 0; k < found; ++k) {
      ASSERT_EQ(index[k], all[k].second) << "query " << q << ", neighbour " << k;
      ASSERT_EQ(distance_sq[k], all[k].first);
    }
    ++compared;
    if (found < wanted) ++short_of_wanted;
  }
  // A key far outside the grid still finds the nearest points; a NaN key finds none.
  ASSERT_EQ(depth.nearest(Eigen::Vector2f(1e9f, -1e9f), std::numeric_limits<double>::infinity(), 3,
                          index.data(), distance_sq.data()),
            3u);
  EXPECT_EQ(
      depth.nearest(Eigen::Vector2f(std::nanf(""), 0.f), 1.0, 3, index.data(), distance_sq.data()),
      0u);
  EXPECT_EQ(compared, 2000);
  EXPECT_GT(short_of_wanted, 100);  // the radius limited some searches
  EXPECT_LT(short_of_wanted, 1900);
}

}  // namespace
}  // namespace posed::vision
