#pragma once
// Test scenes for the visual front end: the M2DGR rig's two cameras looking at textured
// fronto-parallel walls, rendered through each camera's own lens model, so that registration,
// fusion, tracking and depth can be checked against geometry known exactly.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/vision/pinhole_camera.hpp"

namespace posed::vision::scene {

/// The D435i colour camera as calibrated in M2DGR (and the daemon's defaults).
inline PinholeCamera m2dgr_visible() {
  PinholeCamera c;
  c.width = 640;
  c.height = 480;
  c.fx = 617.971050917033;
  c.fy = 616.445131524790;
  c.cx = 327.710279392468;
  c.cy = 253.976983707814;
  c.k1 = 0.148000794688248;
  c.k2 = -0.217835187249065;
  return c;
}

/// The PLUG 617 thermal camera as calibrated in M2DGR.
inline PinholeCamera m2dgr_thermal() {
  PinholeCamera c;
  c.width = 640;
  c.height = 512;
  c.fx = 435.836180277211;
  c.fy = 435.909430631362;
  c.cx = 324.452753232850;
  c.cy = 255.554320082190;
  c.k1 = -0.436107594318055;
  c.k2 = 0.166413618922992;
  return c;
}

/// `extrinsics.T_cam_thermal` of the default config: thermal 0.17 m left of the colour camera.
inline Eigen::Isometry3d m2dgr_T_cam_thermal() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(-0.17, 0, 0);
  return T;
}

/// Smooth value noise in [0, 1] on a unit lattice (deterministic hash per lattice node).
inline double value_noise(double x, double y, std::uint32_t seed) {
  const auto hash = [seed](std::int64_t i, std::int64_t j) {
    std::uint64_t h = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ull ^
                      static_cast<std::uint64_t>(j) * 0xC2B2AE3D27D4EB4Full ^ seed;
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    return static_cast<double>(h & 0xFFFFFF) / static_cast<double>(0xFFFFFF);
  };
  const double fx = std::floor(x), fy = std::floor(y);
  const auto i = static_cast<std::int64_t>(fx), j = static_cast<std::int64_t>(fy);
  double tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);
  ty = ty * ty * (3 - 2 * ty);
  const double a = hash(i, j), b = hash(i + 1, j), c = hash(i, j + 1), d = hash(i + 1, j + 1);
  return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty;
}

/// Surface brightness of a wall at wall coordinates (X, Y) [m], in [0, 1]: several octaves of
/// value noise (cells of 0.6, 0.2 and 0.07 m) and hard-edged tiles, so there are corners to
/// track at any range from 3 to 20 m.
inline double wall_texture(double X, double Y, std::uint32_t seed) {
  const double tiles = (static_cast<std::int64_t>(std::floor(X / 0.45)) +
                        static_cast<std::int64_t>(std::floor(Y / 0.45))) %
                                   2 ==
                               0
                           ? 0.15
                           : 0.0;
  return 0.35 * value_noise(X / 0.6, Y / 0.6, seed) +
         0.3 * value_noise(X / 0.2, Y / 0.2, seed + 1) +
         0.2 * value_noise(X / 0.07, Y / 0.07, seed + 2) + tiles;
}

/// The undistorted normalised ray (x/z, y/z) of every pixel of a camera, row-major.
inline std::vector<Eigen::Vector2d> pixel_rays(const PinholeCamera& camera) {
  std::vector<Eigen::Vector2d> rays(static_cast<std::size_t>(camera.width * camera.height));
  for (int r = 0; r < camera.height; ++r) {
    for (int c = 0; c < camera.width; ++c) {
      Eigen::Vector2d xy(0, 0);
      camera.normalised_from_pixel(Eigen::Vector2d(c, r), xy);
      rays[static_cast<std::size_t>(r * camera.width + c)] = xy;
    }
  }
  return rays;
}

/// Renders the plane z = depth_m of the world frame W (world x, y = wall coordinates) seen by a
/// camera at pose T_world_cam, brightness `gain` x texture + `offset` (grey levels), CV_8UC1.
/// Rays that miss the wall are black.
inline cv::Mat render_wall(const PinholeCamera& camera, const std::vector<Eigen::Vector2d>& rays,
                           const Eigen::Isometry3d& T_world_cam, double depth_m, double gain,
                           double offset, std::uint32_t seed) {
  cv::Mat image(camera.height, camera.width, CV_8UC1);
  const Eigen::Matrix3d R = T_world_cam.linear();
  const Eigen::Vector3d o = T_world_cam.translation();
  for (int r = 0; r < camera.height; ++r) {
    auto* row = image.ptr<std::uint8_t>(r);
    for (int c = 0; c < camera.width; ++c) {
      const Eigen::Vector2d& xy = rays[static_cast<std::size_t>(r * camera.width + c)];
      const Eigen::Vector3d d = R * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
      double value = 0;
      if (d.z() > 1e-9) {
        const double s = (depth_m - o.z()) / d.z();
        if (s > 0) {
          const Eigen::Vector3d p = o + s * d;
          value = offset + gain * wall_texture(p.x(), p.y(), seed);
        }
      }
      row[c] = cv::saturate_cast<std::uint8_t>(value);
    }
  }
  return image;
}

/// Adds zero-mean Gaussian noise of `sigma` grey levels (deterministic for a seed).
inline cv::Mat add_noise(const cv::Mat& image, double sigma, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat noise(image.size(), CV_32FC1);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  cv::Mat f;
  image.convertTo(f, CV_32F);
  f += noise;
  cv::Mat out;
  f.convertTo(out, CV_8U);
  return out;
}

/// A textured grey image without any camera model: `wall_texture` sampled on a pixel grid of
/// `metres_per_px`, brightness gain * texture + offset, shifted by (shift_x_px, shift_y_px).
/// Each pixel averages `supersample`^2 samples over its area, so that sub-pixel shifts of the
/// tiles' hard edges move the image as a camera would see them (no aliasing).
inline cv::Mat texture_image(int width, int height, double metres_per_px, double gain,
                             double offset, std::uint32_t seed, double shift_x_px = 0,
                             double shift_y_px = 0, int supersample = 1) {
  const int n = std::max(1, supersample);
  cv::Mat image(height, width, CV_8UC1);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      double sum = 0;
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          const double x = c - 0.5 + (j + 0.5) / n - shift_x_px;
          const double y = r - 0.5 + (i + 0.5) / n - shift_y_px;
          sum += wall_texture(x * metres_per_px, y * metres_per_px, seed);
        }
      }
      image.at<std::uint8_t>(r, c) = cv::saturate_cast<std::uint8_t>(offset + gain * sum / (n * n));
    }
  }
  return image;
}

}  // namespace posed::vision::scene
