// Texture filtering: the analytic box filter matches a dense average over the footprint, a zero
// footprint is the point sample, large footprints tend to the pattern's mean (no moiré), and the
// footprint of a pixel grows with range and with the slant of the face.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "tools/sim/world.hpp"

namespace posed::sim {
namespace {

/// The texture averaged over n x n point samples spread evenly across the footprint.
double dense_average(std::uint8_t texture, const Eigen::Vector2d& uv, const TextureFootprint& f,
                     int n = 400) {
  double sum = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d s = uv + Eigen::Vector2d(((i + 0.5) / n - 0.5) * f.u_m,
                                                     ((j + 0.5) / n - 0.5) * f.v_m);
      sum += texture_value(texture, s, 3);
    }
  return sum / (n * n);
}

TEST(Texture, ZeroFootprintIsThePointSample) {
  // Inside a bed joint, a brick face, a stripe and a dark checker square.
  EXPECT_DOUBLE_EQ(texture_value(kTextureBricks, {0.1, 0.005}, 3), 0.9);
  const double brick = texture_value(kTextureBricks, {0.1, 0.04}, 3);
  EXPECT_GE(brick, 0.2);
  EXPECT_LE(brick, 0.5);
  EXPECT_DOUBLE_EQ(texture_value(kTextureStripes, {2.05, 0.3}, 3), 1.0);
  EXPECT_DOUBLE_EQ(texture_value(kTextureStripes, {2.5, 0.3}, 3), 0.0);
  EXPECT_DOUBLE_EQ(texture_value(kTextureChecker, {0.1, 0.1}, 3), 0.0);
  EXPECT_DOUBLE_EQ(texture_value(kTextureChecker, {0.3, 0.1}, 3), 1.0);
}

TEST(Texture, BoxFilterMatchesADenseAverage) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pos(-5.0, 5.0), size(0.01, 0.9);
  for (int k = 0; k < 40; ++k) {
    const Eigen::Vector2d uv(pos(rng), pos(rng));
    const TextureFootprint f{size(rng), size(rng)};
    // Stripes and the checkerboard are filtered exactly (up to the dense grid's resolution).
    EXPECT_NEAR(texture_value(kTextureStripes, uv, 3, f), dense_average(kTextureStripes, uv, f),
                5e-3)
        << uv.transpose() << " footprint " << f.u_m << " x " << f.v_m;
    EXPECT_NEAR(texture_value(kTextureChecker, uv, 3, f), dense_average(kTextureChecker, uv, f),
                5e-3)
        << uv.transpose() << " footprint " << f.u_m << " x " << f.v_m;
  }
  // Bricks: exact for a footprint inside one course, close on average beyond.
  for (int k = 0; k < 40; ++k) {
    const Eigen::Vector2d uv(pos(rng), 0.075 * std::floor(pos(rng) / 0.075) + 0.045);
    const TextureFootprint f{0.05, 0.02};
    const double mortar_only = texture_value(kTextureBricks, uv, 3, f);
    EXPECT_NEAR(mortar_only, dense_average(kTextureBricks, uv, f), 1e-2) << uv.transpose();
  }
}

TEST(Texture, LargeFootprintsTendToThePatternsMean) {
  // Point-sampled, a pattern finer than a pixel takes arbitrary values from pixel to pixel
  // (moiré); filtered, neighbouring pixels agree on the mean.
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> pos(-20.0, 20.0);
  const TextureFootprint far{2.0, 2.0};
  struct Case {
    std::uint8_t texture;
    double mean;
    double tolerance;
  };
  // Bricks: mortar covers 1 - 0.87 x 0.96 of the wall at 0.9, bricks 0.35 on average.
  const double brick_mean = (1 - 0.87 * 0.96) * 0.9 + 0.87 * 0.96 * 0.35;
  for (const Case& c : {Case{kTextureStripes, 0.12, 0.04}, Case{kTextureChecker, 0.5, 0.05},
                        Case{kTextureNoise, 0.5, 0.1}, Case{kTextureBricks, brick_mean, 0.03}}) {
    double min_v = 1, max_v = 0, point_min = 1, point_max = 0;
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector2d uv(pos(rng), pos(rng));
      const double v = texture_value(c.texture, uv, 3, far);
      const double p = texture_value(c.texture, uv, 3);
      min_v = std::min(min_v, v);
      max_v = std::max(max_v, v);
      point_min = std::min(point_min, p);
      point_max = std::max(point_max, p);
    }
    EXPECT_NEAR(min_v, c.mean, c.tolerance) << int{c.texture};
    EXPECT_NEAR(max_v, c.mean, c.tolerance) << int{c.texture};
    EXPECT_GT(point_max - point_min, 0.3) << int{c.texture};
  }
}

TEST(Texture, PixelFootprintGrowsWithRangeAndSlant) {
  Box wall;  // faces 0/1 are normal to x: u along y, v along z
  const double pitch = 1.0 / 618.0;
  const TextureFootprint head_on = pixel_footprint(wall, 1, {-1, 0, 0}, 10.0, pitch);
  EXPECT_NEAR(head_on.u_m, 10.0 * pitch, 1e-12);
  EXPECT_NEAR(head_on.v_m, 10.0 * pitch, 1e-12);
  // Seen 60 degrees off the normal, across y: twice as long along u, unchanged along v.
  const double a = std::numbers::pi / 3;
  const TextureFootprint slanted =
      pixel_footprint(wall, 1, {-std::cos(a), std::sin(a), 0}, 10.0, pitch);
  EXPECT_NEAR(slanted.u_m, 2 * 10.0 * pitch, 1e-9);
  EXPECT_NEAR(slanted.v_m, 10.0 * pitch, 1e-9);
  // Grazing: capped, finite.
  const TextureFootprint grazing = pixel_footprint(wall, 1, {0, 1, 0}, 10.0, pitch);
  EXPECT_TRUE(std::isfinite(grazing.u_m));
  EXPECT_GT(grazing.u_m, 40 * 10.0 * pitch);
}

}  // namespace
}  // namespace posed::sim
