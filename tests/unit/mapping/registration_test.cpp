#include "core/mapping/registration.hpp"

#include <gtest/gtest.h>

#include "tests/unit/mapping/synthetic_scene.hpp"

namespace posed::mapping {
namespace {

using test::pose;

TEST(Registration, RecoversAKnownMotionInAFurnishedRoom) {
  const auto room = test::sample_boxes(test::furnished_room(), 0.1f);
  // The query was taken 0.6 m and 8 degrees away; the guess is off by 0.3 m and 3 degrees.
  const Eigen::Isometry3d T_target_source = pose(0.6, -0.3, 0.05, 0.14);
  const auto source = test::transformed(room, T_target_source.inverse(), 0.01, 1);
  const auto target = test::transformed(room, Eigen::Isometry3d::Identity(), 0.01, 2);
  const Eigen::Isometry3d guess = pose(0.4, -0.1, 0.0, 0.09);
  const RegistrationResult r = register_clouds(source, target, guess, RegistrationConfig{});
  ASSERT_TRUE(r.accepted()) << verdict_name(r.verdict) << " rms " << r.rms_m << " overlap "
                            << r.overlap << " constraint " << r.constraint;
  const Eigen::Isometry3d error = T_target_source.inverse() * r.T_target_source;
  EXPECT_LT(error.translation().norm(), 0.02);
  EXPECT_LT(Eigen::AngleAxisd(error.rotation()).angle(), 0.005);
  EXPECT_GT(r.overlap, 0.9);
  EXPECT_GT(r.constraint, 0.05);
}

TEST(Registration, RefusesAPlainCorridorItCannotPinAlongItsAxis) {
  const auto corridor = test::sample_boxes(test::plain_corridor(40.0f), 0.1f);
  // Both clouds are the same corridor; the truth is 3 m along it, the guess says 0. The
  // registration agrees with the guess (nothing tells them apart) and must say so.
  const Eigen::Isometry3d T_target_source = pose(3.0, 0, 0, 0);
  const auto source = test::transformed(corridor, T_target_source.inverse(), 0.01, 3);
  const auto target = test::transformed(corridor, Eigen::Isometry3d::Identity(), 0.01, 4);
  const RegistrationResult r =
      register_clouds(source, target, Eigen::Isometry3d::Identity(), RegistrationConfig{});
  EXPECT_EQ(r.verdict, RegistrationVerdict::kDegenerate)
      << verdict_name(r.verdict) << " constraint " << r.constraint;
  EXPECT_GT(std::abs(r.weakest_direction.x()), 0.95) << r.weakest_direction.transpose();
}

TEST(Registration, RefusesTwoDifferentPlaces) {
  const auto room = test::sample_boxes(test::furnished_room(), 0.1f);
  const auto corridor = test::sample_boxes(test::plain_corridor(20.0f), 0.1f);
  const RegistrationResult r =
      register_clouds(room, corridor, Eigen::Isometry3d::Identity(), RegistrationConfig{});
  EXPECT_FALSE(r.accepted()) << "rms " << r.rms_m << " overlap " << r.overlap;
}

TEST(Registration, SaysSoWhenACloudIsNearlyEmpty) {
  const auto room = test::sample_boxes(test::furnished_room(), 0.1f);
  const std::vector<Eigen::Vector3f> few(room.begin(), room.begin() + 5);
  const RegistrationResult r =
      register_clouds(few, room, Eigen::Isometry3d::Identity(), RegistrationConfig{});
  EXPECT_EQ(r.verdict, RegistrationVerdict::kTooFewPoints);
}

TEST(Registration, ThinningKeepsOnePointPerVoxel) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 100; ++i) {
    points.emplace_back(0.01f * static_cast<float>(i % 10), 0.01f * static_cast<float>(i / 10),
                        0.05f);
  }
  points.emplace_back(5.05f, 5.05f, 5.05f);
  points.emplace_back(std::numeric_limits<float>::quiet_NaN(), 0.f, 0.f);
  const auto thin = thin_cloud(points, 0.5);
  ASSERT_EQ(thin.size(), 2u);
}

}  // namespace
}  // namespace posed::mapping
