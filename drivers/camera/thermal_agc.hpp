#pragma once
// 16-bit -> 8-bit automatic gain control for raw thermal counts (Y16 / Mono16). Radiometric
// cameras deliver 14-16 bit counts of which a scene uses a narrow band; mapping that band onto
// 0..255 is what the camera's own AGC does before MJPEG/YUYV (how M2DGR recorded the PLUG 617).
// Pure and deterministic: a 65536-bin histogram and a 65536-entry LUT allocated once.

#include <cstdint>
#include <memory>
#include <string_view>

namespace posed::drivers::camera {

enum class AgcMode : std::uint8_t {
  kPercentileStretch,      ///< linear map of [low, high] percentile onto [0, 255]
  kHistogramEqualisation,  ///< map through the cumulative histogram (flat output histogram)
};
std::string_view to_string(AgcMode m);

struct AgcConfig {
  AgcMode mode = AgcMode::kPercentileStretch;
  /// counts at or below this percentile map to 0 [%] (percentile stretch)
  double low_percentile = 1.0;
  /// counts at or above this percentile map to 255 [%] (percentile stretch)
  double high_percentile = 99.0;
  /// smallest count span stretched onto 0..255, so a flat scene is not noise-amplified [counts]
  std::uint32_t min_span_counts = 16;
};

/// What one frame's AGC did.
struct AgcStats {
  std::uint16_t low_count = 0;   ///< raw count mapped to 0 [counts]
  std::uint16_t high_count = 0;  ///< raw count mapped to 255 [counts]
  std::uint16_t min_count = 0;   ///< smallest raw count in the frame [counts]
  std::uint16_t max_count = 0;   ///< largest raw count in the frame [counts]
};

class ThermalAgc {
 public:
  explicit ThermalAgc(AgcConfig config = {});
  /// Maps `width` x `height` host-order 16-bit counts to 8 bits. Strides in bytes.
  AgcStats apply(const std::uint16_t* src, std::uint32_t src_stride_bytes, std::uint8_t* dst,
                 std::uint32_t dst_stride_bytes, std::uint32_t width, std::uint32_t height);
  const AgcConfig& config() const { return config_; }

 private:
  AgcConfig config_;
  std::unique_ptr<std::uint32_t[]> histogram_;  // 65536 bins
  std::unique_ptr<std::uint8_t[]> lut_;         // 65536 entries
};

}  // namespace posed::drivers::camera
