#pragma once
// The PLUG 617 thermal camera on the vehicle. One temperature field, two outputs:
//   y8   the camera's 8-bit video after its AGC over the frame's range (as M2DGR recorded it)
//   y16  raw radiometric counts before any AGC (thermal_radiometry.hpp: linear in radiance),
//        little-endian 16-bit words holding 14 significant bits
// Both carry the same surface temperatures (plus texture-driven ±0.5 °C), sky temperature, NETD
// 50 mK temporal noise and fixed-pattern noise (per-pixel and per-column) that grows until a
// flat-field correction (NUC: the shutter closes, frames freeze for 0.3 s, the pattern
// resets); for the same seed the two formats see the same noise. Rendered at half resolution
// and upsampled bilinearly (the optics are soft anyway). The camera has no clock: the host
// stamps frames on arrival.

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <random>
#include <string_view>
#include <vector>

#include "core/time.hpp"
#include "tools/sim/clock_model.hpp"
#include "tools/sim/fast_noise.hpp"
#include "tools/sim/gbuffer.hpp"
#include "tools/sim/sensor_scene.hpp"
#include "tools/sim/thermal_radiometry.hpp"

namespace posed::sim {

/// What the thermal camera sends.
enum class ThermalFormat : std::uint8_t {
  kY8,   ///< 8-bit video after AGC (wire format "y8")
  kY16,  ///< raw counts (wire format "y16")
};
/// "y8" or "y16": the wire format names of drivers/camera/pixel_formats.hpp.
std::string_view to_string(ThermalFormat f);
std::optional<ThermalFormat> thermal_format_from_string(std::string_view s);

struct ThermalCameraConfig {
  CameraIntrinsics intrinsics{640, 512, 435.84, 435.91, 324.45, 255.55, 0, 0, 0, 0};
  /// camera in base_link
  Eigen::Isometry3d T_base_cam = Eigen::Isometry3d::Identity();
  ThermalFormat format = ThermalFormat::kY8;
  /// frame rate on the camera's own oscillator [Hz]
  double rate_hz = 25.0;
  /// temporal noise (NETD) [K]
  double netd_k = 0.05;
  /// fixed-pattern noise growth since the last NUC [K/s]
  double fpn_growth_kps = 0.01;
  /// NUC interval range [s]
  double nuc_min_s = 60.0, nuc_max_s = 180.0;
  /// the y16 mapping from temperature to counts
  RadiometricCalibration radiometry;
  bool noise = true;
};

class ThermalCamera {
 public:
  ThermalCamera(const ThermalCameraConfig& config, const SensorScene& scene,
                const ClockModel& clock, std::uint64_t seed);
  /// True time at which the next frame leaves the camera (its exposure midpoint: the latency
  /// to the host is the clock model's).
  Duration next_send() const;
  /// Renders the next frame into `out`: Y8 (width·height bytes) or Y16 (width·height
  /// little-endian 16-bit words), per the config's format.
  void emit(std::vector<std::byte>& out);
  std::uint64_t frames() const { return index_; }
  std::uint64_t nucs() const { return nucs_; }
  const Radiometry& radiometry() const { return radiometry_; }

 private:
  /// Scene temperatures of the next frame at half resolution into temperature_.
  void render_temperatures(Duration t);

  ThermalCameraConfig config_;
  SensorScene scene_;
  DeviceSchedule schedule_;  // exposures, on the camera's frame oscillator
  std::mt19937_64 rng_;
  FastNoise noise_;
  Radiometry radiometry_;
  PixelRays rays_;  // half resolution
  GBuffer gbuffer_;
  std::vector<float> temperature_;          // half resolution [°C]
  std::vector<float> fpn_pixel_, fpn_col_;  // full resolution unit patterns
  /// where a full-resolution row or column samples the half-resolution render (bilinear)
  struct Tap {
    std::size_t i0 = 0, i1 = 0;
    float f = 0;  // weight of i1
  };
  std::vector<Tap> row_taps_, col_taps_;
  std::vector<std::byte> last_frame_;
  std::uint64_t index_ = 0, nucs_ = 0;
  double last_nuc_s_ = 0, next_nuc_s_ = 0;
  double agc_lo_c_ = 0, agc_hi_c_ = 0;
  bool agc_init_ = false;
};

}  // namespace posed::sim
