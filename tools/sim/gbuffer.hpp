#pragma once
// What a simulated camera sees: for every pixel, the box face its ray meets and how far away.
// The colour, thermal and depth cameras shade these hits; casting is the shared, costly part.
//
// Cost is kept near one BVH ray per 16 pixels: rays are cast on a 4-pixel grid; a 4x4 cell
// whose corners all see the same box face is filled by intersecting each pixel's ray with that
// face's plane, other cells test each pixel against the (≤ 4) boxes their corners saw. Objects
// thinner than the grid step that fall between grid rays can vanish (a pole 60 m away);
// everything else is exact per pixel, including the lens distortion of the intrinsics.

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "tools/sim/bvh.hpp"
#include "tools/sim/world.hpp"

namespace posed::sim {

/// Pinhole + radial-tangential distortion (OpenCV's k1, k2, p1, p2).
struct CameraIntrinsics {
  int width = 640;                                            ///< [px]
  int height = 480;                                           ///< [px]
  double fx = 617.97, fy = 616.45, cx = 327.71, cy = 253.98;  ///< [px]
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;                      ///< [-]
};

/// Rays are cast on every kGridStep-th pixel; the cells between them are filled per pixel.
inline constexpr int kGridStep = 4;
/// Grid points along an image side of `pixels` (the last pixel always included).
inline int grid_points(int pixels) { return (pixels - 1 + kGridStep - 1) / kGridStep + 1; }
/// The pixel of grid point `i` along a side of `pixels`.
inline int grid_pixel(int i, int pixels) { return std::min(i * kGridStep, pixels - 1); }
/// One past the last pixel of cell `i` (between grid points i and i + 1) of `points` points:
/// cells own their first row/column; the last cell also its last.
inline int cell_end(int i, int points, int pixels) {
  return i + 2 == points ? grid_pixel(i + 1, pixels) + 1 : grid_pixel(i + 1, pixels);
}

/// Per-pixel hits of one view.
struct GBuffer {
  int width = 0, height = 0;
  /// box seen by each pixel, -1 = sky / nothing within range
  std::vector<std::int32_t> box;
  /// face of that box
  std::vector<std::uint8_t> face;
  /// distance along the ray [m]
  std::vector<float> t_m;
  /// the grid rays' hits, row-major over grid_points(width) x grid_points(height)
  std::vector<std::int32_t> grid_box;
  std::vector<std::uint8_t> grid_face;
  /// cells between grid points (cells_x = grid_points(width) - 1, ...)
  int cells_x = 0, cells_y = 0;
  /// per cell, row-major: its four corners saw the same face, so every pixel in it lies on
  /// that face's plane (smooth shading can be interpolated across it)
  std::vector<std::uint8_t> plane_cell;
};

/// Unit ray directions of every pixel in the camera frame (x right, y down, z forward),
/// undistorted; at `1/downscale` resolution when downscale > 1.
class PixelRays {
 public:
  PixelRays() = default;
  PixelRays(const CameraIntrinsics& intrinsics, int downscale);
  int width() const { return width_; }
  int height() const { return height_; }
  /// angular pitch of one (downscaled) pixel at the image centre [rad]
  double pixel_angle_rad() const { return pixel_angle_rad_; }
  const Eigen::Vector3d& dir(int x, int y) const {
    return dirs_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                 static_cast<std::size_t>(x)];
  }

 private:
  int width_ = 0, height_ = 0;
  double pixel_angle_rad_ = 0;
  std::vector<Eigen::Vector3d> dirs_;
};

/// Fills `out` for a camera at T_map_cam; hits farther than `max_range_m` are sky.
void render_gbuffer(const World& world, const Bvh& bvh, const PixelRays& rays,
                    const Eigen::Isometry3d& T_map_cam, double max_range_m, GBuffer& out);

/// Rounds a value to the nearest byte value, clamping to [0, 255]: per pixel, so no libm call
/// and no branches (clamp first, then truncate the non-negative value + 0.5).
inline std::uint8_t to_u8(float v) {
  return static_cast<std::uint8_t>(static_cast<int>(std::clamp(v, 0.0f, 255.0f) + 0.5f));
}

}  // namespace posed::sim
