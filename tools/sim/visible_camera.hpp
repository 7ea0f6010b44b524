#pragma once
// The D435i colour camera on the vehicle: Lambertian shading with ambient light, point lights
// (street lights, lamps) with inverse-square falloff, a headlight at the camera, emissive
// surfaces, procedural textures, smoke when the world has some (smoke.hpp); auto-exposure with
// a gain limit (so night stays dark and noisy), shot + read noise, YUYV 4:2:2 BT.601 limited
// range as the D435i's colour node sends it, and the D4xx frame metadata that precedes each
// frame.

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "core/time.hpp"
#include "drivers/camera/d4xx_metadata_writer.hpp"
#include "tools/sim/clock_model.hpp"
#include "tools/sim/fast_noise.hpp"
#include "tools/sim/gbuffer.hpp"
#include "tools/sim/sensor_scene.hpp"

namespace posed::sim {

// The D435i's frame metadata is written by the driver layer's writer (tests use it too).
using drivers::camera::D4xxFrameFacts;
using drivers::camera::D4xxNode;
using drivers::camera::encode_d4xx_metadata;
using drivers::camera::set_usb_arrival;

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
  VisibleCamera(const VisibleCameraConfig& config, const SensorScene& scene,
                const ClockModel& clock, std::uint64_t seed);
  /// True time at which the next frame is complete (exposure midpoint + readout).
  Duration next_send() const;
  /// What the D4xx metadata says about the next frame, which reaches the host at `arrival`.
  D4xxFrameFacts next_metadata(HostTime arrival) const;
  /// Renders the next frame as YUYV (width·height·2 bytes) into `out`.
  void emit(std::vector<std::byte>& out);
  std::uint64_t frames() const { return index_; }
  /// current auto-exposure gain [x]: the amplification the next frame is exposed with
  double gain() const { return gain_; }
  /// the next frame's exposure midpoint on the camera's own clock
  DeviceTime next_exposure_mid() const { return schedule_.device(index_); }

 private:
  VisibleCameraConfig config_;
  SensorScene scene_;
  DeviceSchedule schedule_;  // exposure midpoints
  FastNoise noise_;
  PixelRays rays_;
  GBuffer gbuffer_;
  std::vector<float> irradiance_;       // per pixel, this frame
  std::vector<float> grid_irradiance_;  // per grid point, -1 = not on its pixel's face
  std::uint64_t index_ = 0;
  double gain_ = 1.0;
};

}  // namespace posed::sim
