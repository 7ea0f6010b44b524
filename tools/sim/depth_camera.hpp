#pragma once
// The D435i's depth node on the vehicle: Z16 frames of the left IR imager (the depth frame: x
// right, y down, z forward; rectified, no distortion), depth along the optical axis in
// depth units, 0 = no depth. Ray-cast through the world like the other cameras, then the
// stereo pair's behaviour:
//   error     stereo matching misses the true disparity d = fx·b/z by ~`subpixel_rms_px`
//             (Intel's "subpixel", 0.05-0.1 px), so the depth error grows with z²:
//             RMS(z) = z² · subpixel / (fx · b) (Intel, "Tuning depth cameras for best
//             performance"): 4 mm at 1 m, 37 mm at 3 m, 0.1 m at 5 m with the defaults
//   invalid   (0) outside [min_range, max_range]; on surfaces seen at grazing incidence; on
//             surfaces without texture, which comes from the scene (the material's pattern
//             under ambient light or the headlight) or from the IR projector's dot pattern
//             (fading with distance² and albedo); where the right imager cannot see the surface
//             (the band left of every near object, and the left edge of the image: the
//             left-right check of the D4 ASIC); at half of the pixels on a depth edge
//   speckle   a few pixels match a wrong disparity (±1..6 px)
// The frame's metadata (md_depth_control: gain, exposure, laser power) precedes it.
// Timing: the D435i's own hardware clock (the colour stream's: one ASIC stamps both), free
// running at `rate_hz` with its own phase; a frame is sent half a frame after its exposure
// midpoint (readout and the ASIC's matching).

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

struct DepthCameraConfig {
  /// the rectified left IR imager (distortion terms unused)
  CameraIntrinsics intrinsics{640, 480, 390.43, 390.43, 331.39, 242.19, 0, 0, 0, 0};
  /// the depth frame in base_link
  Eigen::Isometry3d T_base_depth = Eigen::Isometry3d::Identity();
  /// frame rate on the camera's clock [Hz]
  double rate_hz = 15.0;
  /// left to right IR imager [m]
  double baseline_m = 0.0501707;
  /// metres per Z16 count [m]
  double depth_unit_m = 0.001;
  /// the working range; depth outside reads 0 [m]
  double min_range_m = 0.155, max_range_m = 10.0;
  /// RMS disparity error of stereo matching [px]
  double subpixel_rms_px = 0.08;
  /// IR projector power (metadata; scales the projected texture) [mW]
  double laser_power_mw = 150.0;
  /// a surface of albedo 0.5 gets enough texture from the projector alone up to here [m]
  double projector_range_m = 4.0;
  /// surfaces seen more obliquely than this from the normal do not match [deg]; the failure
  /// rate ramps up over the 10 degrees before
  double grazing_limit_deg = 80.0;
  /// fraction of matched pixels that lock onto a wrong disparity [-]
  double speckle_fraction = 0.003;
  /// false: no noise, speckle or random invalidation (geometry tests); the deterministic
  /// invalid cases (range, occlusion, grazing and texture limits) stay
  bool noise = true;
};

/// Why a depth pixel reads what it reads.
enum class DepthPixel : std::uint8_t {
  kValid,       ///< a depth with the modelled error
  kSpeckle,     ///< a depth from a wrong disparity
  kNoHit,       ///< nothing within the render range (sky)
  kOutOfRange,  ///< the true or measured depth is outside [min_range, max_range]
  kGrazing,     ///< the surface is seen too obliquely
  kLowTexture,  ///< neither the scene nor the projector gives the matcher texture
  kOccluded,    ///< the right imager does not see this surface
  kEdge,        ///< on a depth discontinuity, the matching window straddles two surfaces
};

/// The noise-free frame behind the last emit(), for tests.
struct DepthFrameTruth {
  /// true depth along the optical axis per pixel [m]; 0 where nothing was hit
  std::vector<float> z_m;
  /// what the pixel reports
  std::vector<DepthPixel> pixel;
  /// the depth frame in map at the exposure midpoint
  Eigen::Isometry3d T_map_depth = Eigen::Isometry3d::Identity();
};

class DepthCamera {
 public:
  /// `phase`: the depth stream's start relative to the camera clock's whole frame periods.
  DepthCamera(const DepthCameraConfig& config, const SensorScene& scene, const ClockModel& clock,
              std::uint64_t seed, Duration phase = Duration::from_ns(0));
  /// True time at which the next frame is complete.
  Duration next_send() const;
  /// What the D4xx metadata says about the next frame, which reaches the host at `arrival`.
  D4xxFrameFacts next_metadata(HostTime arrival) const;
  /// Renders the next frame as Z16 (width·height little-endian 16-bit words) into `out`;
  /// fills `truth` if given.
  void emit(std::vector<std::byte>& out, DepthFrameTruth* truth = nullptr);
  /// The modelled RMS depth error at depth `z_m` [m].
  double depth_rms_m(double z_m) const;
  std::uint64_t frames() const { return index_; }
  const DepthCameraConfig& config() const { return config_; }

 private:
  /// Marks pixels the right imager cannot see (per row, scanning its projections).
  void mark_occlusions();
  /// Marks pixels on a depth discontinuity (half of them).
  void mark_edges();

  DepthCameraConfig config_;
  SensorScene scene_;
  DeviceSchedule schedule_;  // exposure midpoints
  FastNoise noise_;
  PixelRays rays_;
  GBuffer gbuffer_;
  std::vector<float> z_m_;         // true depth per pixel [m], 0 = no hit
  std::vector<DepthPixel> pixel_;  // per pixel
  std::uint64_t index_ = 0;
  double exposure_us_ = 8500.0;  // of the frame being exposed [us]
  double gain_ = 16.0;           // firmware units, 16 = 1x
};

}  // namespace posed::sim
