// The BVH returns the same nearest hit as testing every box, on random rays in each world.

#include "tools/sim/bvh.hpp"

#include <gtest/gtest.h>

#include <random>

#include "tools/sim/scenarios.hpp"

namespace posed::sim {
namespace {

TEST(Bvh, MatchesBruteForce) {
  for (std::string_view name : scenario_names()) {
    std::string error;
    auto s = make_scenario(name, 11, 30.0, 9.805, error);
    ASSERT_TRUE(s) << error;
    const World& w = s->world;
    const Bvh bvh(w);
    std::mt19937_64 rng(5);
    std::normal_distribution<double> n(0, 1);
    int hits = 0;
    for (int i = 0; i < 3000; ++i) {
      const Eigen::Vector3d o =
          s->trajectory.at(0.02 * i).p_map_base_m + Eigen::Vector3d(0, 0, 0.2);
      const Eigen::Vector3d d = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
      std::optional<RayHit> best;
      for (std::size_t b = 0; b < w.boxes.size(); ++b) {
        auto h = intersect_box(w.boxes[b], o, d, 200.0);
        if (h && (!best || h->t_m < best->t_m)) {
          best = h;
          best->box = static_cast<std::uint32_t>(b);
        }
      }
      const auto got = bvh.cast(o, d, 200.0);
      ASSERT_EQ(best.has_value(), got.has_value()) << name << " ray " << i;
      if (best) {
        ++hits;
        EXPECT_NEAR(best->t_m, got->t_m, 1e-9) << name;
      }
    }
    EXPECT_GT(hits, 1000) << name;
  }
}

TEST(Box, OrientedBoxHitAndFace) {
  Box b;
  b.center_m = {10, 0, 1};
  b.half_extent_m = {1, 2, 1};
  b.R_map_box = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const auto h = intersect_box(b, {0, 0, 1}, {1, 0, 0}, 100);
  ASSERT_TRUE(h);
  // The -x face of a box yawed 0.3 rad: the plane through centre - R·(1,0,0).
  const Eigen::Vector3d n = face_normal_map(b, h->face);
  EXPECT_NEAR(n.dot(Eigen::Vector3d(h->t_m, 0, 1) - b.center_m), 1.0, 1e-12);
  EXPECT_LT(n.x(), 0);
  EXPECT_FALSE(intersect_box(b, {0, 0, 1}, {-1, 0, 0}, 100));
  EXPECT_FALSE(intersect_box(b, {0, 0, 1}, {1, 0, 0}, 5.0));  // beyond t_max
}

}  // namespace
}  // namespace posed::sim
