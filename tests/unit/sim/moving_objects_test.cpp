// posectl sim --dynamic: people and vehicles move along the loop beside the robot, stand on the
// ground, and are what the lidar's rays and the cameras' pixels meet where they are.

#include "tools/sim/moving_objects.hpp"

#include <gtest/gtest.h>

#include "tools/sim/scenarios.hpp"

namespace posed::sim {
namespace {

TEST(MovingObjects, MoveAlongTheLoopOnTheGroundAndAreWhatRaysAndPixelsMeet) {
  std::string error;
  auto s = make_scenario("street_night", 4, 60.0, 9.805, error);
  ASSERT_TRUE(s) << error;
  const std::size_t static_boxes = s->world.boxes.size();
  MovingObjects moving(s->world, s->trajectory, true, 11);
  ASSERT_GE(moving.people(), 2u);
  ASSERT_GE(moving.vehicles(), 1u);
  EXPECT_EQ(s->world.boxes.size(), static_boxes + moving.people() + moving.vehicles());
  EXPECT_NE(moving.describe().find("people"), std::string::npos);

  moving.place(Duration::from_seconds(3.0));
  std::vector<Eigen::Vector3d> at3;
  for (std::size_t k = static_boxes; k < s->world.boxes.size(); ++k) {
    const Box& b = s->world.boxes[k];
    at3.push_back(b.center_m);
    EXPECT_NEAR(b.center_m.z(), b.half_extent_m.z(), 1e-12) << "standing on the ground";
    // A ray from above, straight down onto it, meets it (nothing static is tested here); where
    // two overlap in plan (a vehicle overtaking another through it), the taller one.
    const Eigen::Vector3d from = b.center_m + Eigen::Vector3d(0, 0, 2.5);
    const auto hit = moving.cast(from, Eigen::Vector3d(0, 0, -1), 100.0);
    ASSERT_TRUE(hit);
    EXPECT_GE(hit->box, static_boxes);
    EXPECT_LE(hit->t_m, 2.5 - b.half_extent_m.z() + 1e-9);
    if (hit->box == k) {
      EXPECT_NEAR(hit->t_m, 2.5 - b.half_extent_m.z(), 1e-9);
    }
  }
  // One second later each has moved by about its speed (people 0.7-1.6 m/s, vehicles 3-9 m/s).
  moving.place(Duration::from_seconds(4.0));
  for (std::size_t k = static_boxes; k < s->world.boxes.size(); ++k) {
    const double moved = (s->world.boxes[k].center_m - at3[k - static_boxes]).norm();
    const bool person = k - static_boxes < moving.people();
    // (Less on the inside of a corner, where the offset shortens the way.)
    EXPECT_GT(moved, person ? 0.3 : 1.0) << k;
    EXPECT_LT(moved, person ? 1.8 : 9.5) << k;
  }

  // A camera 6 m from the first person, looking at it: the centre pixel is that person.
  const Box& person = s->world.boxes[static_boxes];
  const Eigen::Vector3d eye = person.center_m + Eigen::Vector3d(0, -6, 0);
  Eigen::Isometry3d T_map_cam = Eigen::Isometry3d::Identity();
  // Camera axes: x right, y down, z forward (+y of map).
  T_map_cam.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  T_map_cam.translation() = eye;
  CameraIntrinsics K;
  const PixelRays rays(K, 4);
  GBuffer g;
  g.width = rays.width();
  g.height = rays.height();
  const auto n = static_cast<std::size_t>(g.width * g.height);
  g.box.assign(n, -1);
  g.face.assign(n, 0);
  g.t_m.assign(n, 0.f);
  moving.overlay(rays, T_map_cam, 150.0, g);
  const std::size_t centre = static_cast<std::size_t>(g.height / 2 * g.width + g.width / 2);
  EXPECT_EQ(g.box[centre], static_cast<std::int32_t>(static_boxes));
  EXPECT_NEAR(g.t_m[centre], 6.0 - person.half_extent_m.y(), 0.3);
  // And nothing where the image looks past it (the top corner, at the sky).
  EXPECT_EQ(g.box[0], -1);
}

}  // namespace
}  // namespace posed::sim
