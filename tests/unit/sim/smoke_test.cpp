// Smoke for the colour camera (smoke.hpp): the schedule is zero outside its interval and dense
// inside, a frame in dense smoke has lost its texture, a world without smoke renders as before,
// and the `smoke` scenario draws its interval where docs/simulator.md says.

#include "tools/sim/smoke.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/unit/sim/test_scene.hpp"
#include "tools/sim/scenarios.hpp"
#include "tools/sim/visible_camera.hpp"

namespace posed::sim {
// Named rather than anonymous: test files build as unity batches.
namespace smoke_test {

SmokeSchedule example() {
  SmokeSchedule s;
  s.start_s = 10;
  s.dense_from_s = 14;
  s.dense_to_s = 30;
  s.clear_s = 36;
  s.dense_extinction_per_m = 3;
  return s;
}

TEST(SmokeSchedule, NoneByDefault) {
  const SmokeSchedule none;
  EXPECT_FALSE(none.any());
  EXPECT_FALSE(World{}.smoke.any());
  for (double t = -1; t < 100; t += 0.25) EXPECT_EQ(none.extinction_per_m(t), 0.0) << t;
}

TEST(SmokeSchedule, ZeroOutsideDenseInsideRampsBetween) {
  const SmokeSchedule s = example();
  EXPECT_TRUE(s.any());
  for (const double t : {-5.0, 0.0, 9.99, 10.0, 36.0, 36.01, 60.0})
    EXPECT_EQ(s.extinction_per_m(t), 0.0) << t;
  for (const double t : {14.0, 20.0, 30.0}) EXPECT_EQ(s.extinction_per_m(t), 3.0) << t;
  EXPECT_NEAR(s.extinction_per_m(12.0), 1.5, 1e-12);  // smoothstep's midpoint
  EXPECT_NEAR(s.extinction_per_m(33.0), 1.5, 1e-12);
  double last = 0;
  for (double t = 10; t <= 14; t += 0.1) {
    EXPECT_GE(s.extinction_per_m(t), last) << t;
    last = s.extinction_per_m(t);
  }
  for (double t = 30; t <= 36; t += 0.1) {
    EXPECT_LE(s.extinction_per_m(t), last) << t;
    last = s.extinction_per_m(t);
  }
}

TEST(SmokeSchedule, HeadlightBackscatterIsTheIntegral) {
  EXPECT_EQ(headlight_backscatter(0.0), 0.0);
  for (const double sigma : {0.1, 0.5, 1.0, 3.0, 10.0}) {
    // σ ∫ exp(-2σs) / (1 + s²) ds by the midpoint rule on a fine grid.
    double sum = 0;
    const double ds = 1e-4;
    for (double s = 0.5 * ds; s < 40.0 / sigma; s += ds)
      sum += std::exp(-2 * sigma * s) / (1 + s * s) * ds;
    EXPECT_NEAR(headlight_backscatter(sigma), sigma * sum, 1e-4) << sigma;
    EXPECT_LT(headlight_backscatter(sigma), 0.5);  // the σ → ∞ limit
  }
  EXPECT_LT(headlight_backscatter(0.5), headlight_backscatter(3.0));
}

TEST(SmokeScenario, IntervalWhereTheDocsSayAndNoSmokeElsewhere) {
  for (const double duration_s : {30.0, 60.0, 120.0, 300.0}) {
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
      std::string error;
      const auto s = make_scenario("smoke", seed, duration_s, 9.805, error);
      ASSERT_TRUE(s) << error;
      const SmokeSchedule& k = s->world.smoke;
      ASSERT_TRUE(k.any());
      EXPECT_GE(k.start_s, 0.30 * duration_s);
      EXPECT_LE(k.start_s, 0.45 * duration_s);
      EXPECT_GT(k.dense_from_s, k.start_s);
      EXPECT_GE(k.dense_to_s - k.dense_from_s, 0.20 * duration_s);
      EXPECT_LE(k.dense_to_s - k.dense_from_s, 0.30 * duration_s);
      EXPECT_GT(k.clear_s, k.dense_to_s);
      EXPECT_LT(k.clear_s, duration_s);  // it clears before the end
      EXPECT_GE(k.dense_extinction_per_m, 2.5);
      // The same inputs, the same smoke.
      const auto again = make_scenario("smoke", seed, duration_s, 9.805, error);
      ASSERT_TRUE(again);
      EXPECT_EQ(again->world.smoke.start_s, k.start_s);
      EXPECT_EQ(again->world.smoke.clear_s, k.clear_s);
    }
  }
  for (const std::string_view name : scenario_names()) {
    if (name == "smoke") continue;
    std::string error;
    const auto s = make_scenario(name, 3, 60.0, 9.805, error);
    ASSERT_TRUE(s) << error;
    EXPECT_FALSE(s->world.smoke.any()) << name;
  }
}

/// A colour camera 3 m in front of a textured wall (shotcrete-like value noise), ambient light
/// only, no sensor noise.
struct TexturedWall {
  explicit TexturedWall(const SmokeSchedule& smoke) : scene(test::forward_camera()) {
    World& w = scene.world();
    w.ambient = 0.3;
    w.headlight = 0.0;
    w.smoke = smoke;
    const auto wall = w.add_material({25, 0.35, kTextureNoise, 0.6, 20, 0, {1, 1, 1}});
    scene.add_box({0, 0, 3.1}, {6, 6, 0.1}, wall);
    config.T_base_cam = test::forward_camera();
    config.noise = false;
  }
  /// The Y plane of every frame up to true time `until_s`, with the frames' true times.
  std::vector<std::vector<double>> frames(double until_s, std::vector<double>& times_s) {
    VisibleCamera camera(config, scene.finish(), ClockModel({0, 20.0, 0, 0}, 0, 1), 7);
    std::vector<std::vector<double>> out;
    std::vector<std::byte> bytes;
    while (true) {
      // A frame is sent half a frame after its exposure midpoint.
      const double t_s = camera.next_send().seconds() - 0.5 / config.rate_hz;
      if (t_s > until_s) break;
      camera.emit(bytes);
      std::vector<double> y(bytes.size() / 2);
      for (std::size_t i = 0; i < y.size(); ++i) y[i] = static_cast<double>(bytes[2 * i]);
      out.push_back(std::move(y));
      times_s.push_back(t_s);
    }
    return out;
  }
  test::CameraTestScene scene;
  VisibleCameraConfig config;
};

/// Standard deviation over mean of the image's centre (the wall fills it).
double contrast(const std::vector<double>& y) {
  double s = 0, s2 = 0, n = 0;
  for (int r = 140; r < 340; ++r)
    for (int c = 200; c < 440; ++c) {
      const double v = y[static_cast<std::size_t>(r * 640 + c)] - 16.0;  // above black
      s += v;
      s2 += v * v;
      n += 1;
    }
  const double mean = s / n;
  return std::sqrt(std::max(0.0, s2 / n - mean * mean)) / mean;
}

TEST(SmokeInTheColourCamera, DenseSmokeTakesTheTextureAndNoneChangesNothing) {
  SmokeSchedule smoke;
  smoke.start_s = 0.4;
  smoke.dense_from_s = 0.7;
  smoke.dense_to_s = 1.3;
  smoke.clear_s = 1.6;
  smoke.dense_extinction_per_m = 3.0;
  TexturedWall smoky(smoke);
  TexturedWall clear_air{SmokeSchedule{}};
  std::vector<double> t_smoky, t_clear;
  const auto with = smoky.frames(2.0, t_smoky);
  const auto without = clear_air.frames(2.0, t_clear);
  ASSERT_EQ(with.size(), without.size());
  ASSERT_GT(with.size(), 25u);
  int before = 0, dense = 0, after = 0;
  for (std::size_t k = 0; k < with.size(); ++k) {
    const double t = t_smoky[k];
    if (t <= smoke.start_s || t >= smoke.clear_s) {
      // No smoke in the air: the very frame a world without smoke gives (the auto-exposure
      // has settled again after the smoke).
      EXPECT_GT(contrast(with[k]), 0.1) << t;
      if (t <= smoke.start_s) {
        EXPECT_EQ(with[k], without[k]) << t;
        ++before;
      } else {
        ++after;
      }
    } else if (t >= smoke.dense_from_s && t <= smoke.dense_to_s) {
      // exp(-3 /m · 3 m) = 1e-4 of the wall's texture left under the airlight.
      EXPECT_LT(contrast(with[k]), 0.02 * contrast(without[k])) << t;
      ++dense;
    }
  }
  EXPECT_GT(before, 3);
  EXPECT_GT(dense, 5);
  EXPECT_GT(after, 3);
}

}  // namespace smoke_test
}  // namespace posed::sim
