#pragma once
// The D435i colour camera and the PLUG 617 thermal camera on the vehicle.
//
// Rendering cost is kept near one BVH ray per 16 pixels: rays are cast on a 4-pixel grid; a
// 4x4 cell whose corners all see the same box face is filled by intersecting each pixel's ray
// with that face's plane, other cells test each pixel against the (≤ 4) boxes their corners
// saw. Objects thinner than the grid step that fall between grid rays can vanish (a pole 60 m
// away); everything else is exact per pixel, including the lens distortion of the intrinsics.
//
// Visible: Lambertian shading with ambient light, point lights (street lights, lamps) with
// inverse-square falloff, a headlight at the camera, emissive surfaces, procedural textures;
// auto-exposure with a gain limit (so night stays dark and noisy), shot + read noise, YUYV 4:2:2
// BT.601 limited range as the D435i's colour node sends it.
// Thermal: surface temperatures (plus texture-driven ±0.5 °C), sky temperature, NETD 50 mK
// temporal noise, fixed-pattern noise (per-pixel and per-column) that grows until a flat-field
// correction (NUC: the shutter closes, frames freeze for 0.3 s, the pattern resets), 8-bit
// AGC over the frame's range as the PLUG 617's video output; rendered at half resolution and
// upsampled bilinearly (the optics are soft anyway).

#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <vector>

#include "core/time.hpp"
#include "tools/sim/bvh.hpp"
#include "tools/sim/clock_model.hpp"
#include "tools/sim/fast_noise.hpp"
#include "tools/sim/trajectory.hpp"
#include "tools/sim/world.hpp"

namespace posed::sim {

/// Pinhole + radial-tangential distortion (OpenCV's k1, k2, p1, p2).
struct CameraIntrinsics {
  int width = 640;                                            ///< [px]
  int height = 480;                                           ///< [px]
  double fx = 617.97, fy = 616.45, cx = 327.71, cy = 253.98;  ///< [px]
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;                      ///< [-]
};

/// Per-pixel hits of one view.
struct GBuffer {
  int width = 0, height = 0;
  /// box seen by each pixel, -1 = sky / nothing within range
  std::vector<std::int32_t> box;
  /// face of that box
  std::vector<std::uint8_t> face;
  /// distance along the ray [m]
  std::vector<float> t_m;
};

/// Unit ray directions of every pixel in the camera frame (x right, y down, z forward),
/// undistorted; at `1/downscale` resolution when downscale > 1.
class PixelRays {
 public:
  PixelRays() = default;
  PixelRays(const CameraIntrinsics& intrinsics, int downscale);
  int width() const { return width_; }
  int height() const { return height_; }
  const Eigen::Vector3d& dir(int x, int y) const {
    return dirs_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                 static_cast<std::size_t>(x)];
  }

 private:
  int width_ = 0, height_ = 0;
  std::vector<Eigen::Vector3d> dirs_;
};

/// Fills `out` for a camera at T_map_cam.
void render_gbuffer(const World& world, const Bvh& bvh, const PixelRays& rays,
                    const Eigen::Isometry3d& T_map_cam, double max_range_m, GBuffer& out);

struct VisibleCameraConfig {
  CameraIntrinsics intrinsics;
  /// camera in base_link
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  /// frame rate on the camera's clock [Hz]
  double rate_hz = 15.0;
  /// the most auto-exposure can amplify a dark scene [x]
  double max_gain = 24.0;
  /// false: no sensor noise
  bool noise = true;
};

class VisibleCamera {
 public:
  VisibleCamera(const VisibleCameraConfig& config, const World& world, const Bvh& bvh,
                const Trajectory& trajectory, const ClockModel& clock, std::uint64_t seed);
  /// True time at which the next frame is complete (exposure midpoint + readout).
  Duration next_send() const;
  /// Renders the next frame as YUYV (width·height·2 bytes) into `out`.
  void emit(std::vector<std::byte>& out);
  std::uint64_t frames() const { return index_; }
  /// current auto-exposure gain [x]: the amplification the next frame is exposed with
  double gain() const { return gain_; }
  /// the next frame's exposure midpoint on the camera's own clock
  DeviceTime next_exposure_mid() const { return exposure_mid(index_); }

 private:
  DeviceTime exposure_mid(std::uint64_t k) const;

  VisibleCameraConfig config_;
  const World& world_;
  const Bvh& bvh_;
  const Trajectory& trajectory_;
  ClockModel clock_;
  std::mt19937_64 rng_;
  FastNoise noise_;
  PixelRays rays_;
  GBuffer gbuffer_;
  std::vector<float> radiance_;
  DeviceTime start_device_;
  std::uint64_t index_ = 0;
  double gain_ = 1.0;
};

struct ThermalCameraConfig {
  CameraIntrinsics intrinsics{640, 512, 435.84, 435.91, 324.45, 255.55, 0, 0, 0, 0};
  /// camera in base_link
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  /// frame rate on the camera's own oscillator [Hz]
  double rate_hz = 25.0;
  /// temporal noise (NETD) [K]
  double netd_k = 0.05;
  /// fixed-pattern noise growth since the last NUC [K/s]
  double fpn_growth_kps = 0.01;
  /// NUC interval range [s]
  double nuc_min_s = 60.0, nuc_max_s = 180.0;
  bool noise = true;
};

class ThermalCamera {
 public:
  ThermalCamera(const ThermalCameraConfig& config, const World& world, const Bvh& bvh,
                const Trajectory& trajectory, const ClockModel& clock, std::uint64_t seed);
  Duration next_send() const;
  /// Renders the next frame as Y8 (width·height bytes) into `out`.
  void emit(std::vector<std::byte>& out);
  std::uint64_t frames() const { return index_; }
  std::uint64_t nucs() const { return nucs_; }

 private:
  DeviceTime exposure_mid(std::uint64_t k) const;

  ThermalCameraConfig config_;
  const World& world_;
  const Bvh& bvh_;
  const Trajectory& trajectory_;
  ClockModel clock_;
  std::mt19937_64 rng_;
  FastNoise noise_;
  PixelRays rays_;  // half resolution
  GBuffer gbuffer_;
  std::vector<float> temperature_;          // half resolution [°C]
  std::vector<float> fpn_pixel_, fpn_col_;  // full resolution unit patterns
  std::vector<std::byte> last_frame_;
  DeviceTime start_device_;
  std::uint64_t index_ = 0, nucs_ = 0;
  double last_nuc_s_ = 0, next_nuc_s_ = 0;
  double agc_lo_c_ = 0, agc_hi_c_ = 0;
  bool agc_init_ = false;
};

}  // namespace posed::sim
